// The mapper process's node over memq://: what it publishes for each frame and tick, how it
// treats hostile frames, snapshot requests, lockstep ordering and checkpoints.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>
#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "map_messages.hpp"
#include "mapper_messages.hpp"
#include "mapper_node.hpp"
#include "mapper_test_util.hpp"
#include "semx/map/map_mirror.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_url.hpp"

namespace semx::mapper {
namespace {

namespace ch = semx::channels;

runtime::NodeOptions memq_node(const std::string& name = "mapper", bool lockstep = false) {
  runtime::NodeOptions o;
  o.name = name;
  o.lcm_url = "memq://";
  o.quiet = true;
  o.status_period_s = 1e6;
  o.lockstep = lockstep;
  return o;
}

MapperConfig small_config() {
  MapperConfig c;
  c.esdf.window = {4.0, 4.0, 2.0};  // 40 x 40 x 20 voxels: fast, and still a real field
  c.streaming.snapshot_period = 0;  // only on request, unless a test says otherwise
  c.streaming.stats_period = 1.0;
  c.streaming.esdf_period = 0;       // an ESDF after every frame, so each can be compared with a reference
  c.integration.frame_period_s = 0;  // every frame integrated, unless a test says otherwise
  return c;
}

// Every message the node handles (its own and the test's), in order.
struct Wire {
  std::vector<std::string> channels;
  std::vector<std::vector<uint8_t>> payloads;

  explicit Wire(runtime::Node& node) {
    node.subscribe_raw(".*", [this](const std::string& c, const uint8_t* d, std::size_t n) {
      channels.push_back(c);
      payloads.emplace_back(d, d + n);
    });
  }
  template <class T>
  std::vector<T> all(const std::string& channel) const {
    std::vector<T> out;
    for (size_t i = 0; i < channels.size(); ++i) {
      if (channels[i] != channel) continue;
      T m;
      EXPECT_EQ(m.decode(payloads[i].data(), 0, static_cast<int>(payloads[i].size())),
                static_cast<int>(payloads[i].size()));
      out.push_back(m);
    }
    return out;
  }
  int count(const std::string& channel) const {
    return static_cast<int>(std::count(channels.begin(), channels.end(), channel));
  }
  int index_of(const std::string& channel, int nth = 0) const {
    for (size_t i = 0; i < channels.size(); ++i) {
      if (channels[i] == channel && nth-- == 0) return static_cast<int>(i);
    }
    return -1;
  }
};

semx::depth_image_t frame_message(const runtime::PinholeCamera& cam, const test::RoomFrame& f, int64_t utime,
                                  bool compress = false) {
  return depth_message(DepthFrame::view(cam, f.pose, f.depth, utime), compress);
}

semx::odometry_t odometry_at(const Eigen::Vector3d& p, int64_t utime) {
  semx::odometry_t m{};
  m.utime = utime;
  for (int i = 0; i < 3; ++i) m.position[i] = p[i];
  m.orientation[0] = 1.0;
  return m;
}

semx::clock_t clock_at(int64_t tick, int64_t utime, bool lockstep) {
  semx::clock_t c{};
  c.tick = tick;
  c.utime = utime;
  c.mode = lockstep ? semx::clock_t::LOCKSTEP : semx::clock_t::REALTIME;
  c.period_us = 10000;
  return c;
}

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "semx_mnode_" + std::to_string(getpid()) + "_" + name;
}

void expect_same(const map::StateGrid& a, const map::StateGrid& b) {
  map::VoxelKey diff;
  EXPECT_TRUE(a.same_states(b, &diff)) << "first difference at " << diff.x << " " << diff.y << " " << diff.z;
  EXPECT_EQ(a.free_voxels(), b.free_voxels());
  EXPECT_EQ(a.occupied_voxels(), b.occupied_voxels());
}

TEST(MapperNode, PublishesTheMappersDeltaAndEsdfForEveryFrameAndStatsAt1Hz) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(5, cam, 5);
  const MapperConfig cfg = small_config();
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  Mapper reference(cfg);

  const Eigen::Vector3d vehicle(3.0, 2.5, 1.3);
  std::vector<map::MapDelta> expected;
  std::vector<std::vector<float>> expected_esdf;
  for (int k = 0; k < 5; ++k) {
    const int64_t utime = k * 33333;
    node.publish(ch::ODOMETRY, odometry_at(vehicle, utime));
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[k], utime, /*compress=*/k % 2 == 1));
    node.drain();
    expected.push_back(
        reference.integrate(DepthFrame::view(cam, frames[k].pose, frames[k].depth, utime)).delta);
    reference.update_esdf(vehicle);
    expected_esdf.push_back(reference.esdf().distance);
  }

  const auto updates = wire.all<semx::map_update_t>(ch::MAP_UPDATE);
  ASSERT_EQ(updates.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    map::MapDelta got;
    ASSERT_TRUE(map::from_message(updates[k], got));
    EXPECT_EQ(got.seq, k + 1);
    EXPECT_EQ(got.seq, expected[k].seq);
    EXPECT_EQ(got.utime, k * 33333);
    EXPECT_EQ(got.resolution, 0.1);
    ASSERT_EQ(got.changes.size(), expected[k].changes.size()) << "frame " << k;
    EXPECT_GT(got.changes.size(), 0u);
    for (size_t i = 0; i < got.changes.size(); ++i) {
      ASSERT_EQ(got.changes[i].key, expected[k].changes[i].key);
      ASSERT_EQ(got.changes[i].state, expected[k].changes[i].state);
    }
  }

  const auto esdfs = wire.all<semx::esdf_local_t>(ch::ESDF_LOCAL);
  ASSERT_EQ(esdfs.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const auto& e = esdfs[k];
    EXPECT_EQ(e.nx, 40);
    EXPECT_EQ(e.ny, 40);
    EXPECT_EQ(e.nz, 20);
    EXPECT_EQ(e.num_cells, 40 * 40 * 20);
    EXPECT_EQ(e.map_seq, k + 1);
    EXPECT_EQ(e.utime, k * 33333);
    EXPECT_TRUE(e.unknown_as_occupied);
    // Centred on the odometry position, not on the camera.
    EXPECT_NEAR(e.origin[0] + 0.5 * e.nx * e.resolution, vehicle.x(), 0.1);
    EXPECT_NEAR(e.origin[1] + 0.5 * e.ny * e.resolution, vehicle.y(), 0.1);
    EXPECT_NEAR(e.origin[2] + 0.5 * e.nz * e.resolution, vehicle.z(), 0.1);
    EXPECT_EQ(e.distance, expected_esdf[k]) << "frame " << k;
  }
  // The message converts back into the same field (origin key, layout, queries).
  map::EsdfGrid g;
  ASSERT_TRUE(map::from_message(esdfs.back(), g));
  EXPECT_EQ(g.origin, reference.esdf().origin);
  for (const Eigen::Vector3d& p : {vehicle, Eigen::Vector3d(2.2, 1.9, 0.8), Eigen::Vector3d(4.1, 3.3, 1.9)}) {
    double d = 0, d_ref = 1;
    Eigen::Vector3d grad, grad_ref;
    ASSERT_TRUE(g.interpolate(p, &d, &grad));
    ASSERT_TRUE(reference.esdf().interpolate(p, &d_ref, &grad_ref));
    EXPECT_EQ(d, d_ref);
    EXPECT_EQ(grad, grad_ref);
  }
  // Each frame's MAP_UPDATE comes before its ESDF_LOCAL.
  for (int k = 0; k < 5; ++k) EXPECT_LT(wire.index_of(ch::MAP_UPDATE, k), wire.index_of(ch::ESDF_LOCAL, k));

  // MAP_STATS: once at the start, then every second of message time (ticks here).
  EXPECT_EQ(wire.count(ch::MAP_STATS), 1);
  for (int64_t t = 1; t <= 4; ++t) node.publish(ch::SIM_CLOCK, clock_at(t, t * 500000, false));
  node.drain();
  const auto stats = wire.all<semx::map_stats_t>(ch::MAP_STATS);
  ASSERT_EQ(stats.size(), 3u) << "t = 0, 1.0 and 2.0 s";
  EXPECT_EQ(stats[1].utime, 1000000);
  EXPECT_EQ(stats[2].utime, 2000000);
  const map::MapStats ref = reference.stats();
  EXPECT_EQ(stats[2].seq, 5);
  EXPECT_EQ(stats[2].free_voxels, ref.free_voxels);
  EXPECT_EQ(stats[2].occupied_voxels, ref.occupied_voxels);
  EXPECT_EQ(stats[2].frontier_voxels, ref.frontier_voxels);
  EXPECT_DOUBLE_EQ(stats[2].known_m3, ref.known_m3);
  EXPECT_EQ(stats[2].frames_integrated, 5);
  EXPECT_EQ(stats[2].frames_rejected, 0);
  expect_same(mn.mapper().map().grid(), reference.map().grid());
  EXPECT_EQ(node.counters().malformed, 0);
}

TEST(MapperNode, EmptyDeltasArePublishedToo) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(1, cam, 1);
  MapperConfig cfg = small_config();
  cfg.esdf.enabled = false;
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  // The same view over and over: after the log-odds saturate nothing changes state.
  for (int k = 0; k < 12; ++k) node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[0], k * 33333));
  node.drain();
  const auto updates = wire.all<semx::map_update_t>(ch::MAP_UPDATE);
  ASSERT_EQ(updates.size(), 12u);
  EXPECT_EQ(updates.back().seq, 12);
  EXPECT_EQ(updates.back().num_voxels, 0);
  EXPECT_EQ(wire.count(ch::ESDF_LOCAL), 0) << "esdf.enabled = false";
}

TEST(MapperNode, HostileAndMalformedFramesAreCountedAndDropped) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(1, cam, 1);
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNodeOptions quiet;
  quiet.quiet = true;
  MapperNode mn(node, small_config(), quiet);
  const semx::depth_image_t good = frame_message(cam, frames[0], 1000);

  std::vector<std::pair<std::string, semx::depth_image_t>> bad;
  auto variant = [&](const char* what, const std::function<void(semx::depth_image_t&)>& edit) {
    semx::depth_image_t m = good;
    edit(m);
    bad.emplace_back(what, m);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  variant("NaN position", [&](auto& m) { m.info.sensor_position[1] = nan; });
  variant("infinite position", [&](auto& m) { m.info.sensor_position[0] = HUGE_VAL; });
  variant("far position", [&](auto& m) { m.info.sensor_position[2] = 1e9; });
  variant("NaN orientation", [&](auto& m) { m.info.sensor_orientation[0] = nan; });
  variant("zero quaternion", [&](auto& m) {
    for (double& q : m.info.sensor_orientation) q = 0;
  });
  variant("quaternion of norm 2", [&](auto& m) {
    for (double& q : m.info.sensor_orientation) q *= 2;
  });
  variant("fx zero", [&](auto& m) { m.info.fx = 0; });
  variant("fy negative", [&](auto& m) { m.info.fy = -80; });
  variant("cx NaN", [&](auto& m) { m.info.cx = nan; });
  variant("ranges inverted", [&](auto& m) { std::swap(m.info.min_range, m.info.max_range); });
  variant("max range NaN", [&](auto& m) { m.info.max_range = nan; });
  variant("width too small for the payload", [&](auto& m) { m.info.width = 100; });
  variant("height zero", [&](auto& m) { m.info.height = 0; });
  variant("negative width", [&](auto& m) { m.info.width = -160; });
  variant("huge image", [&](auto& m) {
    m.info.width = 1 << 15;
    m.info.height = 1 << 15;
  });
  variant("payload one byte short", [&](auto& m) {
    m.depth_data.pop_back();
    m.num_depth_bytes = static_cast<int32_t>(m.depth_data.size());
  });
  variant("unknown compression", [&](auto& m) { m.compression = 7; });
  variant("ZLIB flag on raw bytes", [&](auto& m) { m.compression = semx::depth_image_t::ZLIB; });
  variant("zlib of the wrong size", [&](auto& m) {
    std::vector<uint8_t> raw(m.depth_data.begin(), m.depth_data.end() - 2);
    uLongf n = compressBound(raw.size());
    std::vector<uint8_t> z(n);
    compress2(z.data(), &n, raw.data(), raw.size(), 1);
    z.resize(n);
    m.depth_data = z;
    m.num_depth_bytes = static_cast<int32_t>(z.size());
    m.compression = semx::depth_image_t::ZLIB;
  });
  variant("zlib bomb", [&](auto& m) {
    std::vector<uint8_t> raw(static_cast<size_t>(m.info.width) * m.info.height * 2 * 64, 0);
    uLongf n = compressBound(raw.size());
    std::vector<uint8_t> z(n);
    compress2(z.data(), &n, raw.data(), raw.size(), 9);
    z.resize(n);
    m.depth_data = z;
    m.num_depth_bytes = static_cast<int32_t>(z.size());
    m.compression = semx::depth_image_t::ZLIB;
  });
  for (const auto& [what, m] : bad) node.publish(ch::CAMERA_DEPTH, m);
  // Bytes that are not a depth_image_t at all: garbage, a truncated message, another type.
  std::vector<uint8_t> bytes(good.getEncodedSize());
  good.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  node.publish_raw(ch::CAMERA_DEPTH, bytes.data(), bytes.size() / 2);
  const std::vector<uint8_t> garbage(1000, 0xA5);
  node.publish_raw(ch::CAMERA_DEPTH, garbage.data(), garbage.size());
  node.publish(ch::CAMERA_DEPTH, odometry_at(Eigen::Vector3d::Zero(), 0));
  node.drain();

  const int64_t n_bad = static_cast<int64_t>(bad.size()) + 3;
  EXPECT_EQ(node.counters().malformed, n_bad);
  EXPECT_EQ(mn.frames_malformed(), n_bad);
  EXPECT_EQ(node.counters().handler_errors, 0);
  EXPECT_EQ(mn.counters().frames_received, 0);
  EXPECT_EQ(mn.mapper().seq(), 0);
  EXPECT_EQ(mn.mapper().map().grid().known_voxels(), 0);
  EXPECT_EQ(wire.count(ch::MAP_UPDATE), 0);
  EXPECT_EQ(wire.count(ch::ESDF_LOCAL), 0);

  // A frame the integrator refuses (its range does not overlap the mapper's 0-5 m): counted as
  // rejected, no delta.
  semx::depth_image_t far = good;
  far.info.min_range = 6.0;
  far.info.max_range = 9.0;
  node.publish(ch::CAMERA_DEPTH, far);
  node.drain();
  EXPECT_EQ(mn.counters().frames_rejected, 1);
  EXPECT_EQ(mn.mapper().seq(), 0);

  // The node is intact: the good frame still goes through, and MAP_STATS counts the rest.
  node.publish(ch::CAMERA_DEPTH, good);
  node.publish(ch::SIM_CLOCK, clock_at(1, 2000000, false));
  node.drain();
  EXPECT_EQ(mn.mapper().seq(), 1);
  ASSERT_EQ(wire.count(ch::MAP_UPDATE), 1);
  const auto stats = wire.all<semx::map_stats_t>(ch::MAP_STATS);
  ASSERT_FALSE(stats.empty());
  EXPECT_EQ(stats.back().frames_integrated, 1);
  EXPECT_EQ(stats.back().frames_rejected, n_bad + 1);
  EXPECT_EQ(node.status().malformed, n_bad);
}

TEST(MapperNode, MapRequestIsAnsweredWithTheWholeMap) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(3, cam, 3);
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, small_config());
  for (int k = 0; k < 3; ++k) node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[k], k * 33333));
  node.drain();
  EXPECT_EQ(wire.count(ch::MAP_SNAPSHOT), 0) << "snapshot_period 0: only on request";
  node.publish(ch::MAP_REQUEST, map::request_message("planner", -1, 0));
  node.drain();
  const auto snaps = wire.all<semx::map_snapshot_t>(ch::MAP_SNAPSHOT);
  ASSERT_EQ(snaps.size(), 1u);
  EXPECT_EQ(snaps[0].seq, 3);
  EXPECT_EQ(snaps[0].utime, 66666);
  EXPECT_EQ(snaps[0].encoding, map::kSnapshotBlocksZlib);
  map::StateGrid copy(0.1);
  map::decode_snapshot(map::from_message(snaps[0]), copy);
  expect_same(copy, mn.mapper().map().grid());
  EXPECT_EQ(mn.counters().requests, 1);

  // A request that is not a request (last_seq below -1) is malformed, not answered.
  node.publish(ch::MAP_REQUEST, map::request_message("planner", -7, 0));
  node.drain();
  EXPECT_EQ(wire.count(ch::MAP_SNAPSHOT), 1);
  EXPECT_EQ(node.counters().malformed, 1);
}

TEST(MapperNode, PeriodicSnapshotsFollowMessageTime) {
  MapperConfig cfg = small_config();
  cfg.streaming.snapshot_period = 2.0;
  cfg.streaming.stats_period = 0;  // off
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  for (int64_t t = 0; t <= 500; ++t) node.publish(ch::SIM_CLOCK, clock_at(t, t * 10000, false));
  node.drain();
  const auto snaps = wire.all<semx::map_snapshot_t>(ch::MAP_SNAPSHOT);
  ASSERT_EQ(snaps.size(), 3u) << "t = 0, 2 and 4 s";
  EXPECT_EQ(snaps[1].utime, 2000000);
  EXPECT_EQ(snaps[2].utime, 4000000);
  EXPECT_EQ(wire.count(ch::MAP_STATS), 0);
}

// 0.5 s of 30 Hz frames on the simulator's 10 ms tick grid (utimes 0, 40000, 70000, 100000, ...),
// each after an odometry message, cycling through `frames`.
template <class Camera, class Frames>
void publish_30hz_frames(runtime::Node& node, const Camera& cam, const Frames& frames) {
  const Eigen::Vector3d vehicle(3.0, 2.5, 1.3);
  for (int k = 0; k <= 15; ++k) {
    const int64_t utime = (k * 100000 / 3 + 9999) / 10000 * 10000;
    node.publish(ch::ODOMETRY, odometry_at(vehicle, utime));
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[k % frames.size()], utime));
    node.drain();
  }
}

// The default streaming.esdf_period (0.2 s of message time): the first frame's ESDF at once, then
// one with the first frame at or after each due time; the others get only their MAP_UPDATE.
TEST(MapperNode, DefaultEsdfPeriodSendsFiveEsdfsPerSecondOfFrames) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(4, cam, 4);
  MapperConfig cfg = small_config();
  cfg.streaming.esdf_period = MapperConfig().streaming.esdf_period;
  ASSERT_DOUBLE_EQ(cfg.streaming.esdf_period, 0.2);
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  publish_30hz_frames(node, cam, frames);
  EXPECT_EQ(wire.count(ch::MAP_UPDATE), 16);
  std::vector<int64_t> esdf_utimes;
  for (const auto& e : wire.all<semx::esdf_local_t>(ch::ESDF_LOCAL)) esdf_utimes.push_back(e.utime);
  EXPECT_EQ(esdf_utimes, (std::vector<int64_t>{0, 200000, 400000}));
  EXPECT_EQ(mn.counters().esdfs, 3);
}

// The default integration.frame_period_s (0.1 s of message time): of 30 Hz frames the first and
// then one per 0.1 s are integrated (and get a MAP_UPDATE); the others are skipped unread.
TEST(MapperNode, DefaultFramePeriodIntegratesTenFramesASecond) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(4, cam, 4);
  MapperConfig cfg = small_config();
  cfg.integration.frame_period_s = MapperConfig().integration.frame_period_s;
  ASSERT_DOUBLE_EQ(cfg.integration.frame_period_s, 0.1);
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  publish_30hz_frames(node, cam, frames);
  std::vector<int64_t> integrated;
  for (const auto& u : wire.all<semx::map_update_t>(ch::MAP_UPDATE)) integrated.push_back(u.utime);
  EXPECT_EQ(integrated, (std::vector<int64_t>{0, 100000, 200000, 300000, 400000, 500000}));
  EXPECT_EQ(mn.counters().frames_skipped, 10);
  EXPECT_EQ(mn.frames_malformed(), 0);
}

// streaming.lockstep_delay (here 0.04 s): in LOCKSTEP a frame is integrated on the worker and
// its outputs go out in the handler of the first tick 0.04 s after it, before that tick's ack;
// they are exactly the outputs of the synchronous node. A tick with stats due publishes every
// frame in flight first, so MAP_STATS describes the map of the last MAP_UPDATE.
TEST(MapperNode, LockstepDelayPublishesAFramesOutputsAtAFixedLaterTick) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(4, cam, 4);
  MapperConfig cfg = small_config();
  cfg.streaming.stats_period = 0.15;
  cfg.streaming.lockstep_delay = 0.04;
  runtime::Node node(memq_node("mapper", /*lockstep=*/true));
  Wire wire(node);
  MapperNode mn(node, cfg);
  Mapper reference(cfg);
  const Eigen::Vector3d vehicle(3.0, 2.5, 1.3);
  const std::vector<int64_t> frame_ticks = {3, 7, 10, 13};
  std::vector<map::MapDelta> expected;
  std::vector<std::vector<float>> expected_esdf;
  node.publish(ch::SIM_CLOCK, clock_at(0, 0, true));
  node.drain();
  for (int64_t t = 1; t <= 20; ++t) {
    const auto f = std::find(frame_ticks.begin(), frame_ticks.end(), t);
    if (f != frame_ticks.end()) {
      const auto& frame = frames[f - frame_ticks.begin()];
      node.publish(ch::ODOMETRY, odometry_at(vehicle, t * 10000));
      node.publish(ch::CAMERA_DEPTH, frame_message(cam, frame, t * 10000));
      expected.push_back(
          reference.integrate(DepthFrame::view(cam, frame.pose, frame.depth, t * 10000)).delta);
      reference.update_esdf(vehicle);
      expected_esdf.push_back(reference.esdf().distance);
    }
    node.publish(ch::SIM_CLOCK, clock_at(t, t * 10000, true));
    node.drain();
  }
  EXPECT_EQ(mn.frames_in_flight(), 0u);
  const auto updates = wire.all<semx::map_update_t>(ch::MAP_UPDATE);
  const auto esdfs = wire.all<semx::esdf_local_t>(ch::ESDF_LOCAL);
  ASSERT_EQ(updates.size(), 4u);
  ASSERT_EQ(esdfs.size(), 4u);
  // The wire position of SIM_CLOCK(k) and SIM_ACK(k).
  auto position = [&](const std::string& channel, int64_t tick) {
    for (size_t i = 0; i < wire.channels.size(); ++i) {
      if (wire.channels[i] != channel) continue;
      int64_t got = -1;
      if (channel == ch::SIM_CLOCK) {
        semx::clock_t c{};
        c.decode(wire.payloads[i].data(), 0, static_cast<int>(wire.payloads[i].size()));
        got = c.tick;
      } else {
        semx::ack_t a{};
        a.decode(wire.payloads[i].data(), 0, static_cast<int>(wire.payloads[i].size()));
        got = a.tick;
      }
      if (got == tick) return static_cast<int>(i);
    }
    return -1;
  };
  // Stats are due at 0.15 s (tick 15): frame 13 goes out there, early, with the stats after it.
  const std::vector<int64_t> publish_ticks = {7, 11, 14, 15};
  for (size_t k = 0; k < 4; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    map::MapDelta got;
    ASSERT_TRUE(map::from_message(updates[k], got));
    EXPECT_EQ(got.seq, expected[k].seq);
    EXPECT_EQ(got.utime, frame_ticks[k] * 10000);
    ASSERT_EQ(got.changes.size(), expected[k].changes.size());
    for (size_t i = 0; i < got.changes.size(); ++i) {
      ASSERT_EQ(got.changes[i].key, expected[k].changes[i].key);
      ASSERT_EQ(got.changes[i].state, expected[k].changes[i].state);
    }
    EXPECT_EQ(esdfs[k].utime, frame_ticks[k] * 10000);
    EXPECT_EQ(esdfs[k].distance, expected_esdf[k]);
    const int at = wire.index_of(ch::MAP_UPDATE, static_cast<int>(k));
    EXPECT_GT(at, position(ch::SIM_CLOCK, publish_ticks[k]));
    EXPECT_LT(at, position(ch::SIM_ACK, publish_ticks[k]));
    EXPECT_LT(wire.index_of(ch::ESDF_LOCAL, static_cast<int>(k)), position(ch::SIM_ACK, publish_ticks[k]));
  }
  const auto stats = wire.all<semx::map_stats_t>(ch::MAP_STATS);
  ASSERT_EQ(stats.size(), 2u) << "t = 0 and 0.15 s";
  EXPECT_EQ(stats[1].seq, 4);
  EXPECT_GT(wire.index_of(ch::MAP_STATS, 1), wire.index_of(ch::MAP_UPDATE, 3));
  expect_same(mn.mapper().map().grid(), reference.map().grid());
}

// The running process's loop over real sockets: a frame in flight waits for its tick however
// many spins end without a message (every fragment of a depth frame that arrives alone ends one;
// here a 2 ms status period does), and goes out without it only after a second of silence, when
// the clock has stopped. Counting ten empty spins instead published frames early on a loaded
// machine, and runs of one seed flew differently.
TEST(MapperNode, AFrameInFlightWaitsForItsTickUntilTheClockIsSilent) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(2, cam, 2);
  MapperConfig cfg = small_config();
  cfg.streaming.stats_period = 0;
  cfg.streaming.lockstep_delay = 0.04;
  const std::string url = runtime::udpm_url_for_port(30000 + (static_cast<int>(getpid()) % 2000) * 10 + 3);
  runtime::NodeOptions mo = memq_node("mapper", /*lockstep=*/true);
  mo.lcm_url = url;
  mo.status_period_s = 0.002;
  runtime::Node mapper_node(mo);
  MapperNode mn(mapper_node, cfg);
  runtime::NodeOptions to = memq_node("driver");
  to.lcm_url = url;
  runtime::Node driver(to);
  std::vector<std::pair<int64_t, int64_t>> updates;  // (frame utime, last tick sent when it came)
  int64_t last_tick = -1;
  driver.subscribe<semx::map_update_t>(
      ch::MAP_UPDATE, [&](const semx::map_update_t& m) { updates.emplace_back(m.utime, last_tick); });
  std::thread loop([&] { mn.run(); });
  auto listen = [&](double seconds, size_t until_updates = SIZE_MAX) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end && updates.size() < until_updates) driver.spin_once(5);
  };
  auto tick = [&](int64_t t) {
    last_tick = t;
    driver.publish(ch::SIM_CLOCK, clock_at(t, t * 10000, true));
    listen(0.02);
  };
  listen(0.2);  // the mapper's socket is up
  tick(0);
  driver.publish(ch::ODOMETRY, odometry_at(Eigen::Vector3d(3, 2.5, 1.3), 10000));
  driver.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[0], 10000));
  tick(1);
  listen(0.5);  // a slow tick: hundreds of empty spins, half a second
  EXPECT_TRUE(updates.empty()) << "published before its tick";
  for (int64_t t = 2; t <= 6; ++t) tick(t);
  listen(0.8, 1);  // a loaded machine may take a while; nothing is in flight once it is out
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_EQ(updates[0].first, 10000);
  // Not before tick 5 (0.01 s + lockstep_delay 0.04 s; which tick exactly is the memq test's).
  EXPECT_GE(updates[0].second, 5);
  // The clock stops with a frame in flight: it goes out after a second of silence.
  driver.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[1], 70000));
  tick(7);
  listen(0.5);
  EXPECT_EQ(updates.size(), 1u);
  listen(2.0, 2);
  ASSERT_EQ(updates.size(), 2u);
  EXPECT_EQ(updates[1].first, 70000);
  mapper_node.stop();
  loop.join();
}

// In LOCKSTEP the node's outputs for tick k are on the wire before its SIM_ACK(k), and a
// MAP_REQUEST is answered at the next tick, so every run answers at the same point.
TEST(MapperNode, LockstepOutputsPrecedeTheAckAndRequestsWaitForTheNextTick) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(2, cam, 2);
  runtime::Node node(memq_node("mapper", /*lockstep=*/true));
  Wire wire(node);
  MapperNode mn(node, small_config());

  node.publish(ch::ODOMETRY, odometry_at(Eigen::Vector3d(3, 2.5, 1.3), 0));
  node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[0], 0));
  node.publish(ch::SIM_CLOCK, clock_at(0, 0, true));
  node.drain();
  const int update = wire.index_of(ch::MAP_UPDATE), esdf = wire.index_of(ch::ESDF_LOCAL),
            stats = wire.index_of(ch::MAP_STATS), ack = wire.index_of(ch::SIM_ACK);
  ASSERT_GE(update, 0);
  ASSERT_GE(esdf, 0);
  ASSERT_GE(stats, 0);
  ASSERT_GE(ack, 0);
  EXPECT_LT(update, ack);
  EXPECT_LT(esdf, ack);
  EXPECT_LT(stats, ack);
  EXPECT_EQ(wire.all<semx::ack_t>(ch::SIM_ACK)[0].tick, 0);

  // A request between ticks: answered by the tick-1 handler, before SIM_ACK(1).
  node.publish(ch::MAP_REQUEST, map::request_message("planner", -1, 0));
  node.drain();
  EXPECT_EQ(wire.count(ch::MAP_SNAPSHOT), 0) << "held for the next tick";
  node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[1], 10000));
  node.publish(ch::SIM_CLOCK, clock_at(1, 10000, true));
  node.drain();
  const int snap = wire.index_of(ch::MAP_SNAPSHOT), ack1 = wire.index_of(ch::SIM_ACK, 1);
  ASSERT_GE(snap, 0);
  ASSERT_GE(ack1, 0);
  EXPECT_LT(snap, ack1);
  EXPECT_EQ(wire.all<semx::map_snapshot_t>(ch::MAP_SNAPSHOT)[0].seq, 2) << "includes the tick's frame";
  EXPECT_EQ(wire.all<semx::map_snapshot_t>(ch::MAP_SNAPSHOT)[0].utime, 10000);
}

TEST(MapperNode, CheckpointsOnMessageTimeAndRestoresOnStart) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(4, cam, 4);
  const std::string path = temp_file("periodic.ckpt");
  std::remove(path.c_str());
  MapperConfig cfg = small_config();
  cfg.checkpoint.path = path;
  cfg.checkpoint.period = 1.0;
  int64_t seq_saved = 0;
  {
    runtime::Node node(memq_node());
    MapperNode mn(node, cfg);
    EXPECT_NE(mn.startup_note().find("no checkpoint"), std::string::npos) << mn.startup_note();
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[0], 0));
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[1], 500000));
    node.drain();
    EXPECT_FALSE(std::filesystem::exists(path)) << "the first checkpoint is a period after the start";
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[2], 1000000));
    node.drain();
    ASSERT_TRUE(std::filesystem::exists(path));
    EXPECT_EQ(mn.counters().checkpoints, 1);
    EXPECT_EQ(read_checkpoint_info(path).seq, 3);
    EXPECT_EQ(read_checkpoint_info(path).utime, 1000000);
    node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[3], 1200000));
    node.drain();
    EXPECT_EQ(read_checkpoint_info(path).seq, 3) << "not yet due";
    EXPECT_TRUE(mn.checkpoint_now()) << "what run() does on shutdown";
    EXPECT_FALSE(mn.checkpoint_now()) << "nothing changed since";
    EXPECT_EQ(read_checkpoint_info(path).seq, 4);
    seq_saved = mn.mapper().seq();
  }
  // A restarted mapper continues from the file, with the sequence jump that makes clients resync.
  runtime::Node node(memq_node());
  Wire wire(node);
  MapperNode mn(node, cfg);
  EXPECT_NE(mn.startup_note().find("restored"), std::string::npos) << mn.startup_note();
  EXPECT_EQ(mn.mapper().seq(), seq_saved + Mapper::kRestoreSequenceJump);
  Mapper reference(cfg);
  for (const auto& f : frames) reference.integrate(DepthFrame::view(cam, f.pose, f.depth));
  expect_same(mn.mapper().map().grid(), reference.map().grid());
  node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[0], 0));
  node.drain();
  ASSERT_EQ(wire.count(ch::MAP_UPDATE), 1);
  EXPECT_EQ(wire.all<semx::map_update_t>(ch::MAP_UPDATE)[0].seq,
            seq_saved + Mapper::kRestoreSequenceJump + 1);
  std::remove(path.c_str());
}

// A mapper killed between checkpoints (no checkpoint on exit) comes back with every delta it
// had sent: the checkpoint, then the journal of the deltas published after it. A delta the crash
// cut short in the journal was never sent (the journal is written first) and is left out.
TEST(MapperNode, AKilledMapperComesBackWithEveryDeltaItSent) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(5, cam, 4);
  const std::string path = temp_file("killed.ckpt");
  std::remove(path.c_str());
  std::remove((path + ".journal").c_str());
  MapperConfig cfg = small_config();
  cfg.checkpoint.path = path;
  cfg.checkpoint.period = 1.0;
  std::vector<semx::map_update_t> sent;
  {
    runtime::Node node(memq_node());
    Wire wire(node);
    MapperNode mn(node, cfg);
    const int64_t at[] = {0, 500000, 1000000, 1200000, 1400000};
    for (int i = 0; i < 5; ++i) node.publish(ch::CAMERA_DEPTH, frame_message(cam, frames[i], at[i]));
    node.drain();
    EXPECT_EQ(read_checkpoint_info(path).seq, 3) << "checkpointed at 1 s";
    sent = wire.all<semx::map_update_t>(ch::MAP_UPDATE);
    ASSERT_EQ(sent.size(), 5u);
  }  // killed: no checkpoint on the way out
  auto mirror_of = [&](size_t deltas) {
    map::MapMirror m(cfg.occupancy.resolution);
    for (size_t i = 0; i < deltas; ++i) {
      map::MapDelta d;
      EXPECT_TRUE(map::from_message(sent[i], d));
      EXPECT_EQ(m.apply(d), map::MapMirror::DeltaResult::kApplied);
    }
    return m;
  };
  const auto journal_size = std::filesystem::file_size(path + ".journal");
  {
    runtime::Node node(memq_node());
    MapperNode mn(node, cfg);
    EXPECT_NE(mn.startup_note().find("replayed 2 map updates"), std::string::npos) << mn.startup_note();
    expect_same(mn.mapper().map().grid(), mirror_of(5).grid());
    EXPECT_GT(mn.mapper().seq(), sent.back().seq) << "clients see a gap and resynchronise";
    EXPECT_EQ(std::filesystem::file_size(path + ".journal"), 0u) << "a checkpoint holds the replayed deltas";
    EXPECT_EQ(read_checkpoint_info(path).seq + Mapper::kRestoreSequenceJump, mn.mapper().seq());
  }
  // Once more, with the last journal record cut short: the deltas before it come back.
  std::remove(path.c_str());
  {
    runtime::StateJournal tmp(path + ".journal", runtime::state_kind("MAPJ"), true);
    for (const auto& m : sent) {
      std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
      m.encode(b.data(), 0, static_cast<int>(b.size()));
      tmp.append(b);
    }
  }
  std::filesystem::resize_file(path + ".journal", std::filesystem::file_size(path + ".journal") - 7);
  EXPECT_GT(journal_size, 0u);
  runtime::Node node(memq_node());
  MapperNode mn(node, cfg);
  EXPECT_NE(mn.startup_note().find("replayed 4 map updates"), std::string::npos) << mn.startup_note();
  expect_same(mn.mapper().map().grid(), mirror_of(4).grid());
  std::remove(path.c_str());
  std::remove((path + ".journal").c_str());
}

TEST(MapperNode, BadCheckpointIsAnErrorNamingTheFileUnlessIgnored) {
  const std::string path = temp_file("bad.ckpt");
  {
    std::ofstream f(path, std::ios::binary);
    f << "SEMXMAP this is not a checkpoint";
  }
  MapperConfig cfg = small_config();
  MapperNodeOptions o;
  o.checkpoint_path = path;
  {
    runtime::Node node(memq_node());
    try {
      MapperNode mn(node, cfg, o);
      FAIL() << "a corrupt checkpoint must not be accepted";
    } catch (const MapIoError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--ignore-bad-checkpoint"), std::string::npos) << e.what();
    }
  }
  o.ignore_bad_checkpoint = true;
  o.quiet = true;
  runtime::Node node(memq_node());
  MapperNode mn(node, cfg, o);
  EXPECT_EQ(mn.mapper().seq(), 0);
  EXPECT_NE(mn.startup_note().find("ignored"), std::string::npos) << mn.startup_note();
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::exists(path + ".bad")) << "kept aside, not overwritten";
  std::remove((path + ".bad").c_str());

  // A checkpoint in a directory that does not exist is a config error at start, not a
  // failure half an hour later.
  o.checkpoint_path = temp_file("no_such_dir") + "/map.ckpt";
  runtime::Node node2(memq_node());
  EXPECT_THROW(MapperNode(node2, cfg, o), runtime::ConfigError);
}

}  // namespace
}  // namespace semx::mapper
