// map::MapClient against a live MapperNode, over two memq:// nodes joined by a link the test controls:
// MAP_UPDATEs are lost on the way, the client asks for snapshots, and its mirror must end equal
// to the mapper's map, voxel for voxel.
#include <gtest/gtest.h>
#include <semx/clock_t.hpp>

#include <functional>
#include <set>
#include <string>
#include <vector>

#include "map_client.hpp"
#include "map_messages.hpp"
#include "mapper_messages.hpp"
#include "mapper_node.hpp"
#include "mapper_test_util.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::mapper {
namespace {

namespace ch = semx::channels;

runtime::NodeOptions memq_node(const std::string& name, bool lockstep = false) {
  runtime::NodeOptions o;
  o.name = name;
  o.lcm_url = "memq://";
  o.quiet = true;
  o.status_period_s = 1e6;
  o.lockstep = lockstep;
  return o;
}

// Messages a node handled on some channels, waiting to be carried to the other node.
struct Outbox {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> queue;
  Outbox(runtime::Node& node, const std::set<std::string>& channels) {
    node.subscribe_raw(".*", [this, channels](const std::string& c, const uint8_t* d, std::size_t n) {
      if (channels.count(c)) queue.emplace_back(c, std::vector<uint8_t>(d, d + n));
    });
  }
};

int64_t update_seq(const std::vector<uint8_t>& bytes) {
  semx::map_update_t m;
  EXPECT_GT(m.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  return m.seq;
}

struct LinkResult {
  int64_t lost = 0;
  int64_t snapshots_carried = 0;
};

// Runs `frames` through a mapper node and carries its map messages to a client node, losing
// the MAP_UPDATEs whose seq is in `lost`. With `ticks`, SIM_CLOCK goes to the client after each
// frame (as the simulator's clock would) and the client applies messages on ticks.
void run_link(const std::vector<test::RoomFrame>& frames, const std::set<int64_t>& lost, bool ticks,
              map::MapClientOptions client_options, const std::function<void(map::MapClient&)>& setup,
              const std::function<void(const MapperNode&, const map::MapClient&, const LinkResult&)>& check) {
  const auto cam = test::small_camera();
  MapperConfig cfg;
  cfg.esdf.enabled = false;
  cfg.streaming.snapshot_period = 0;  // recovery only by request
  runtime::Node a(memq_node("mapper"));
  runtime::Node b(memq_node("planner", ticks));
  Outbox from_mapper(a, {ch::MAP_UPDATE, ch::MAP_SNAPSHOT});
  Outbox from_client(b, {ch::MAP_REQUEST});
  MapperNode mapper(a, cfg);
  map::MapClient client(b, client_options);
  if (setup) setup(client);
  LinkResult result;

  auto carry = [&]() {
    a.drain();
    for (auto& [c, bytes] : from_mapper.queue) {
      if (c == ch::MAP_UPDATE && lost.count(update_seq(bytes))) {
        ++result.lost;
        continue;
      }
      result.snapshots_carried += c == ch::MAP_SNAPSHOT;
      b.publish_raw(c, bytes.data(), bytes.size());
    }
    from_mapper.queue.clear();
    b.drain();
    for (auto& [c, bytes] : from_client.queue) a.publish_raw(c, bytes.data(), bytes.size());
    from_client.queue.clear();
  };
  int64_t tick = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    const int64_t utime = static_cast<int64_t>(k) * 100000;
    a.publish(ch::CAMERA_DEPTH, depth_message(DepthFrame::view(cam, frames[k].pose, frames[k].depth, utime)));
    carry();
    if (ticks) {
      semx::clock_t c{};
      c.tick = tick++;
      c.utime = utime + 50000;
      c.mode = semx::clock_t::LOCKSTEP;
      b.publish(ch::SIM_CLOCK, c);
      carry();
    }
  }
  // Let the last answers arrive (and, with ticks, be applied).
  for (int i = 0; i < 4; ++i) {
    carry();
    if (ticks) {
      semx::clock_t c{};
      c.tick = tick++;
      c.utime = static_cast<int64_t>(frames.size() + i) * 100000 + 50000;
      c.mode = semx::clock_t::LOCKSTEP;
      b.publish(ch::SIM_CLOCK, c);
    }
  }
  carry();
  check(mapper, client, result);
}

void expect_mirror_equals_map(const map::MapClient& client, const MapperNode& mapper) {
  ASSERT_TRUE(client.has_mirror());
  EXPECT_TRUE(client.in_sync());
  EXPECT_FALSE(client.mirror().needs_snapshot());
  EXPECT_EQ(client.mirror().seq(), mapper.mapper().seq());
  map::VoxelKey diff;
  EXPECT_TRUE(client.mirror().grid().same_states(mapper.mapper().map().grid(), &diff))
      << "first difference at " << diff.x << " " << diff.y << " " << diff.z;
  EXPECT_EQ(client.mirror().grid().free_voxels(), mapper.mapper().map().grid().free_voxels());
  EXPECT_EQ(client.mirror().grid().occupied_voxels(), mapper.mapper().map().grid().occupied_voxels());
  EXPECT_EQ(client.mirror().count_frontiers(), mapper.mapper().map().count_frontiers());
}

TEST(MapClient, MirrorEqualsTheMapAfterLostUpdates) {
  const auto frames = test::room_frames(16, test::small_camera(), 16);
  map::MapClientOptions o;  // resolution adopted from the mapper
  run_link(frames, {3, 7, 8, 13}, /*ticks=*/false, o, nullptr,
           [](const MapperNode& mapper, const map::MapClient& client, const LinkResult& link) {
             EXPECT_EQ(client.apply_mode(), map::MapClientOptions::Apply::kImmediately);
             expect_mirror_equals_map(client, mapper);
             EXPECT_EQ(link.lost, 4);
             EXPECT_EQ(client.mirror().counters().gaps, 3) << "7 and 8 are one gap";
             // The request at start and one per gap, each answered by one snapshot.
             EXPECT_EQ(client.counters().requests, 4);
             EXPECT_EQ(mapper.counters().requests, 4);
             EXPECT_EQ(link.snapshots_carried, 4);
             EXPECT_EQ(client.mirror().counters().snapshots_applied, 3);
             EXPECT_EQ(client.mirror().counters().deltas_applied, 16 - 4 - 3)
                 << "every delivered delta but the three that revealed a gap";
           });
}

TEST(MapClient, OnTickModeAppliesHeldMessagesAtTicksAndConverges) {
  const auto frames = test::room_frames(12, test::small_camera(), 12);
  map::MapClientOptions o;
  o.resolution = 0.1;
  int64_t deltas = 0, resets = 0;
  run_link(
      frames, {2, 9}, /*ticks=*/true, o,
      [&](map::MapClient& client) {
        client.on_delta([&](const map::MapDelta&) { ++deltas; });
        client.on_reset([&] { ++resets; });
      },
      [&](const MapperNode& mapper, const map::MapClient& client, const LinkResult& link) {
        EXPECT_EQ(client.apply_mode(), map::MapClientOptions::Apply::kOnTick) << "a lockstep participant";
        expect_mirror_equals_map(client, mapper);
        EXPECT_EQ(link.lost, 2);
        EXPECT_EQ(client.mirror().counters().gaps, 2);
        EXPECT_EQ(deltas, client.mirror().counters().deltas_applied);
        EXPECT_EQ(resets, client.mirror().counters().snapshots_applied);
        EXPECT_GE(resets, 2);
      });
}

TEST(MapClient, CallbacksReportAppliedDeltasAndResets) {
  runtime::Node node(memq_node("planner"));
  map::MapClientOptions o;
  o.resolution = 0.1;
  map::MapClient client(node, o);
  int deltas = 0, resets = 0;
  client.on_delta([&](const map::MapDelta& d) {
    ++deltas;
    EXPECT_EQ(d.seq, deltas);
  });
  client.on_reset([&] { ++resets; });
  EXPECT_EQ(client.counters().requests, 1) << "asks for the map at start";
  EXPECT_FALSE(client.in_sync()) << "has not heard from a mapper";

  map::MapDelta d1{1, 0, 0.1, {{{0, 0, 0}, map::VoxelState::kFree}}};
  node.publish(ch::MAP_UPDATE, map::to_message(d1));
  node.drain();
  EXPECT_TRUE(client.in_sync());
  EXPECT_EQ(deltas, 1);
  // seq 3 after 1: a gap. The start-up request is still outstanding (no snapshot came), so the
  // next one waits for request_interval_s (0.5 s) of message time.
  map::MapDelta d3{3, 200000, 0.1, {{{2, 0, 0}, map::VoxelState::kOccupied}}};
  node.publish(ch::MAP_UPDATE, map::to_message(d3));
  node.drain();
  EXPECT_FALSE(client.in_sync());
  EXPECT_EQ(client.counters().requests, 1) << "rate-limited: the start-up request is outstanding";
  map::MapDelta d4{4, 600000, 0.1, {{{3, 0, 0}, map::VoxelState::kFree}}};
  node.publish(ch::MAP_UPDATE, map::to_message(d4));
  node.drain();
  EXPECT_EQ(client.counters().requests, 2) << "0.6 s of message time later";
  // The answer: the map at seq 2; then 3 and 4 come from the mirror's buffer.
  map::StateGrid at2(0.1);
  at2.set_state({0, 0, 0}, map::VoxelState::kFree);
  at2.set_state({1, 0, 0}, map::VoxelState::kFree);
  map::MapSnapshot s = map::encode_snapshot(at2, 2, 600000);
  node.publish(ch::MAP_SNAPSHOT, map::to_message(s));
  node.drain();
  EXPECT_TRUE(client.in_sync());
  EXPECT_EQ(client.seq(), 4);
  EXPECT_EQ(resets, 1);
  EXPECT_EQ(deltas, 1) << "deltas that came with a snapshot are covered by the reset";
  EXPECT_EQ(client.mirror().state(map::VoxelKey{2, 0, 0}), map::VoxelState::kOccupied);

  // Malformed map messages are counted by the node and leave the mirror alone.
  semx::map_update_t bad = map::to_message(map::MapDelta{5, 0, 0.1, {{{9, 9, 9}, map::VoxelState::kFree}}});
  bad.state[0] = 5;
  node.publish(ch::MAP_UPDATE, bad);
  semx::map_snapshot_t bad_snap = map::to_message(s);
  bad_snap.resolution = -1;
  node.publish(ch::MAP_SNAPSHOT, bad_snap);
  node.drain();
  EXPECT_EQ(node.counters().malformed, 2);
  EXPECT_EQ(client.seq(), 4);
  EXPECT_TRUE(client.in_sync());
}

TEST(MapClient, FixedResolutionIgnoresAnotherMappersMessages) {
  runtime::Node node(memq_node("planner"));
  map::MapClientOptions o;
  o.resolution = 0.1;
  o.quiet = true;
  map::MapClient client(node, o);
  node.publish(ch::MAP_UPDATE,
               map::to_message(map::MapDelta{1, 0, 0.2, {{{0, 0, 0}, map::VoxelState::kFree}}}));
  node.drain();
  EXPECT_EQ(client.counters().resolution_mismatches, 1);
  EXPECT_EQ(client.seq(), 0);
  EXPECT_FALSE(client.in_sync());
}

}  // namespace
}  // namespace semx::mapper
