// The simulator process's node over memq://: what it publishes, in which order, and how it
// treats commands, good and bad.
#include <gtest/gtest.h>

#include <algorithm>
#include <semx/ack_t.hpp>
#include <semx/camera_info_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/control_cmd_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/sim_event_t.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <tuple>
#include <string>
#include <vector>

#include "semx/runtime/channels.hpp"
#include "simulator_messages.hpp"
#include "simulator_node.hpp"
#include "test_util.hpp"

using namespace semx;
using namespace semx::simulator;

namespace {

struct Captured {
  std::vector<std::string> channels;
  std::vector<std::vector<uint8_t>> payloads;
};

runtime::NodeOptions memq_node() {
  runtime::NodeOptions o;
  o.name = "simulator";
  o.lcm_url = "memq://";
  o.follow_clock = false;
  o.quiet = true;
  o.status_period_s = 1e6;
  return o;
}

SimulatorNodeOptions lockstep(int64_t ticks) {
  SimulatorNodeOptions o;
  o.clock.mode = runtime::ClockMode::kLockstep;
  o.clock.max_ticks = ticks;
  o.progress_every_s = 0;
  return o;
}

// Runs `ticks` lockstep ticks of env1 and captures every message, in publish order. With
// `stop_after` >= 0 the simulator is dropped after that tick (as if killed); `o` may save its
// state or resume from it (then the tick count starts where it resumed).
Captured run(int64_t ticks, const std::function<void(runtime::Node&, int64_t tick)>& before_tick = nullptr,
             int64_t stop_after = -1, SimulatorNodeOptions o = lockstep(0)) {
  SimulatorConfig cfg;
  cfg.depth_noise.enabled = true;  // noise must be seeded too
  cfg.detection_noise.enabled = true;
  cfg.imu.accel_bias_random_walk = 0.01;  // the IMU's biases and generator must come back too
  Simulator sim(test::shipped("env1"), cfg);
  runtime::Node node(memq_node());
  Captured c;
  node.subscribe_raw(".*", [&](const std::string& ch, const uint8_t* d, std::size_t n) {
    c.channels.push_back(ch);
    c.payloads.emplace_back(d, d + n);
  });
  o.clock.max_ticks = ticks;
  SimulatorNode sn(sim, node, o);
  double wall = 0;
  int64_t tick = sn.resumed_at() + 1;
  while (true) {
    if (before_tick) before_tick(node, tick);
    if (!sn.poll(wall += 0.001)) break;
    node.drain();
    if (tick == stop_after) break;
    ++tick;
  }
  node.drain();
  return c;
}

}  // namespace

TEST(SimulatorNode, PublishesSensorsBeforeEachTickAtTheirRates) {
  const Captured c = run(101);  // ticks 0..100: one simulated second
  int odometry = 0, imu = 0, depth = 0, labels = 0, rgb = 0, clock = 0;
  int64_t last_tick = -1;
  for (std::size_t i = 0; i < c.channels.size(); ++i) {
    const auto& ch = c.channels[i];
    odometry += ch == "ODOMETRY";
    imu += ch == "IMU";
    depth += ch == "CAMERA_DEPTH";
    labels += ch == "CAMERA_LABELS";
    rgb += ch == "CAMERA_RGB";
    if (ch == "SIM_CLOCK") {
      semx::clock_t m;
      ASSERT_EQ(m.decode(c.payloads[i].data(), 0, static_cast<int>(c.payloads[i].size())),
                static_cast<int>(c.payloads[i].size()));
      EXPECT_EQ(m.tick, last_tick + 1);
      EXPECT_EQ(m.utime, m.tick * 10000);
      last_tick = m.tick;
      ++clock;
    }
  }
  EXPECT_EQ(clock, 101);
  EXPECT_EQ(odometry, 101) << "100 Hz plus the initial state";
  EXPECT_NEAR(imu, 200, 1);
  EXPECT_EQ(depth, 31) << "30 Hz plus the initial view";
  EXPECT_EQ(depth, labels);
  EXPECT_EQ(depth, rgb);
  EXPECT_EQ(c.channels.back(), "SIM_CLOCK") << "a tick's data comes before its SIM_CLOCK";
}

TEST(SimulatorNode, FramesCarryTheirPoseAndDecodeToTheRenderedImage) {
  const Captured c = run(4);
  for (std::size_t i = 0; i < c.channels.size(); ++i) {
    if (c.channels[i] != "CAMERA_DEPTH") continue;
    semx::depth_image_t m;
    ASSERT_GT(m.decode(c.payloads[i].data(), 0, static_cast<int>(c.payloads[i].size())), 0);
    EXPECT_EQ(m.info.width, 640);
    EXPECT_EQ(m.info.height, 480);
    EXPECT_EQ(m.info.fx, 320.0);
    const auto start = test::shipped("env1").start;
    EXPECT_NEAR(m.info.sensor_position[0], start.position.x(), 1e-9);
    std::vector<uint8_t> raw;
    ASSERT_TRUE(image_bytes(m.compression, m.depth_data, 640u * 480u * 2u, raw));
    int valid = 0;
    for (std::size_t k = 0; k < raw.size(); k += 2) valid += (raw[k] | raw[k + 1] << 8) != 0;
    EXPECT_GT(valid, 640 * 480 / 2) << "most pixels see something in env1";
    return;
  }
  FAIL() << "no depth frame";
}

TEST(SimulatorNode, CompressedImagesRoundTrip) {
  SimulatorConfig cfg;
  Simulator sim(test::shipped("env1"), cfg);
  CameraFrame f;
  sim.render_camera(f);
  using runtime::ImageCompression;
  for (auto codec : {ImageCompression::kNone, ImageCompression::kZlib, ImageCompression::kRle}) {
    const bool compress = codec != ImageCompression::kNone;
    const auto d = depth_message(f, codec);
    std::vector<uint8_t> raw;
    ASSERT_TRUE(image_bytes(d.compression, d.depth_data, f.depth.data.size() * 2, raw));
    for (std::size_t k = 0; k < f.depth.data.size(); ++k) {
      ASSERT_EQ(static_cast<uint16_t>(raw[2 * k] | raw[2 * k + 1] << 8), f.depth.data[k]);
    }
    const auto l = label_message(f, codec);
    ASSERT_TRUE(image_bytes(l.label_compression, l.label_data, f.class_label.data.size() * 4, raw));
    EXPECT_EQ(raw[0] | raw[1] << 8, f.class_label.data[0]);
    if (compress) {
      EXPECT_LT(l.label_data.size(), f.class_label.data.size()) << "labels compress well";
    }
  }
  std::vector<uint8_t> out;
  EXPECT_FALSE(image_bytes(1, std::vector<uint8_t>{1, 2, 3}, 100, out));
  EXPECT_FALSE(image_bytes(0, std::vector<uint8_t>{1, 2, 3}, 100, out));
}

// The node encodes RGB from runs and labels from their two planes, not through
// runtime::encode_image: the payloads must be the very bytes encode_image gives for the image.
TEST(SimulatorNode, FastEncodersGiveTheCodecsPayloads) {
  using runtime::ImageCompression;
  auto packed_labels = [](const CameraFrame& f) {
    std::vector<uint8_t> raw;
    for (std::size_t i = 0; i < f.class_label.data.size(); ++i) {
      for (uint16_t v : {f.class_label.data[i], f.instance_label.data[i]}) {
        raw.push_back(static_cast<uint8_t>(v & 0xFF));
        raw.push_back(static_cast<uint8_t>(v >> 8));
      }
    }
    return raw;
  };
  auto expect_same = [&](const CameraFrame& image, const CameraFrame& runs) {
    for (auto codec : {ImageCompression::kRle, ImageCompression::kNone, ImageCompression::kZlib}) {
      SCOPED_TRACE(static_cast<int>(codec));
      const auto a = rgb_message(image, codec), b = rgb_message(runs, codec);
      EXPECT_EQ(a.rgb_compression, b.rgb_compression);
      EXPECT_EQ(a.rgb_data, b.rgb_data);
      ImageCompression used;
      const auto want = runtime::encode_image(packed_labels(image), 4, codec, used);
      const auto l = label_message(image, codec);
      EXPECT_EQ(l.label_compression, static_cast<int8_t>(used));
      EXPECT_EQ(l.label_data, want);
    }
  };

  // Rendered frames, from the start pose of each world and from a few yaws.
  for (const char* name : {"env1", "env2", "env3"}) {
    SCOPED_TRACE(name);
    SimulatorConfig cfg;
    Simulator sim(test::shipped(name), cfg);
    for (int k = 0; k < 3; ++k) {
      CameraFrame image, runs;
      sim.render_camera(image, kRenderAll);
      sim.render_camera(runs, kRenderDepth | kRenderLabels | kRenderRgbRuns);
      EXPECT_TRUE(runs.rgb.empty());
      EXPECT_EQ(runs.rgb_runs, rgb_runs(image.rgb));
      expect_same(image, runs);
      sim.command(ControlCommand::velocity({0, 0, 0}, 1.5));
      for (int i = 0; i < 300; ++i) sim.step();
    }
  }

  // Made-up images: one colour (runs split at the 16-bit count), and noise RLE cannot shrink
  // (sent raw, in both cases).
  CameraFrame flat, flat_runs, noise, noise_runs;
  for (CameraFrame* f : {&flat, &flat_runs, &noise, &noise_runs}) {
    f->camera.width = 400;
    f->camera.height = 300;
    f->class_label.resize(400, 300);
    f->instance_label.resize(400, 300);
  }
  flat.channels = noise.channels = kRenderLabels | kRenderRgb;
  flat_runs.channels = noise_runs.channels = kRenderLabels | kRenderRgbRuns;
  flat.rgb = Image<Rgb>(400, 300, Rgb{1, 2, 3});
  noise.rgb.resize(400, 300);
  uint32_t x = 12345;
  for (std::size_t i = 0; i < noise.rgb.data.size(); ++i) {
    x = x * 1664525u + 1013904223u;
    noise.rgb.data[i] = Rgb{static_cast<uint8_t>(x >> 24), static_cast<uint8_t>(x >> 16), 7};
    noise.class_label.data[i] = static_cast<uint16_t>(x >> 20);
    noise.instance_label.data[i] = static_cast<uint16_t>(i / 3);
  }
  flat_runs.rgb_runs = rgb_runs(flat.rgb);
  noise_runs.rgb_runs = rgb_runs(noise.rgb);
  ASSERT_EQ(flat_runs.rgb_runs.size(), 1u);
  expect_same(flat, flat_runs);
  expect_same(noise, noise_runs);
  EXPECT_EQ(rgb_message(noise_runs, ImageCompression::kRle).rgb_compression, 0) << "noise is sent raw";
  EXPECT_EQ(label_message(noise, ImageCompression::kRle).label_compression, 0) << "noise is sent raw";
}

TEST(SimulatorNode, VelocityCommandsMoveTheVehicleAndBadOnesAreDropped) {
  double first_x = 0, last_x = 0;
  bool have_first = false;
  int64_t malformed = 0;
  const Captured c = run(101, [&](runtime::Node& node, int64_t tick) {
    semx::control_cmd_t cmd{};
    cmd.utime = tick * 10000;
    cmd.mode = semx::control_cmd_t::VELOCITY;
    cmd.setpoint[0] = 0.3;
    cmd.yaw_mode = semx::control_cmd_t::YAW_RATE;
    if (tick % 10 == 5) cmd.setpoint[1] = std::nan("");  // must be dropped, not obeyed
    node.publish("CONTROL_CMD", cmd);
    malformed = node.counters().malformed;
  });
  for (std::size_t i = 0; i < c.channels.size(); ++i) {
    if (c.channels[i] != "ODOMETRY") continue;
    semx::odometry_t m{};
    ASSERT_GT(m.decode(c.payloads[i].data(), 0, static_cast<int>(c.payloads[i].size())), 0);
    if (!have_first) first_x = m.position[0];
    have_first = true;
    last_x = m.position[0];
    EXPECT_TRUE(std::isfinite(m.position[1]));
  }
  EXPECT_GT(last_x - first_x, 0.15) << "0.3 m/s for a second with a first-order response";
  EXPECT_GE(malformed, 9) << "NaN commands are counted as malformed";
}

// A simulator killed mid-episode and restarted with its state file goes on from its last tick:
// everything it publishes after the restart is what the simulator that was never killed
// published after that tick, byte for byte (vehicle, sensor counters, noise, IMU generator).
TEST(SimulatorNode, ResumesFromItsStateAsIfNeverStopped) {
  auto commands = [](runtime::Node& node, int64_t tick) {
    semx::control_cmd_t cmd{};
    cmd.utime = tick * 10000;
    cmd.mode = semx::control_cmd_t::VELOCITY;
    cmd.setpoint[0] = 0.4 * std::sin(0.05 * static_cast<double>(tick));
    cmd.setpoint[1] = 0.2;
    cmd.yaw_mode = semx::control_cmd_t::YAW_RATE;
    cmd.yaw_rate = 0.5;
    if (tick % 7 != 3) node.publish("CONTROL_CMD", cmd);
  };
  const Captured whole = run(160, commands);
  const std::string state = ::testing::TempDir() + "/sim_state_" + std::to_string(getpid());
  SimulatorNodeOptions o = lockstep(0);
  o.state_path = state;
  const Captured before = run(160, commands, 97, o);
  o.resume = true;
  const Captured after = run(160, commands, -1, o);
  // Where the first run stopped: just after SIM_CLOCK(97).
  auto tick_of = [](const std::vector<uint8_t>& p) {
    semx::clock_t m{};
    return m.decode(p.data(), 0, static_cast<int>(p.size())) > 0 ? m.tick : -1;
  };
  std::size_t at = 0;
  for (; at < whole.channels.size(); ++at) {
    if (whole.channels[at] == "SIM_CLOCK" && tick_of(whole.payloads[at]) == 97) break;
  }
  ASSERT_LT(at, whole.channels.size());
  std::vector<std::size_t> rest;
  for (std::size_t i = at + 1; i < whole.channels.size(); ++i)
    if (whole.channels[i] != "NODE_STATUS") rest.push_back(i);
  std::vector<std::size_t> resumed;
  for (std::size_t i = 0; i < after.channels.size(); ++i)
    if (after.channels[i] != "NODE_STATUS") resumed.push_back(i);
  ASSERT_EQ(resumed.size(), rest.size());
  ASSERT_GT(rest.size(), 100u);
  // A tick also names its publishers and how much each has sent (docs/runtime.md, "Lost
  // messages"): the restarted simulator is a new publisher. Its time is what must be the same.
  const auto clock_time = [](const std::vector<uint8_t>& p) {
    semx::clock_t m{};
    EXPECT_GT(m.decode(p.data(), 0, static_cast<int>(p.size())), 0);
    return std::make_tuple(m.tick, m.utime, m.mode, m.period_us);
  };
  for (std::size_t k = 0; k < rest.size(); ++k) {
    ASSERT_EQ(after.channels[resumed[k]], whole.channels[rest[k]]) << k;
    if (whole.channels[rest[k]] == "SIM_CLOCK") {
      EXPECT_EQ(clock_time(after.payloads[resumed[k]]), clock_time(whole.payloads[rest[k]])) << " #" << k;
      continue;
    }
    EXPECT_EQ(after.payloads[resumed[k]], whole.payloads[rest[k]]) << whole.channels[rest[k]] << " #" << k;
  }
  // No second start of the episode, and ticks only go on.
  for (std::size_t i = 0; i < after.channels.size(); ++i) {
    if (after.channels[i] == "SIM_CLOCK") {
      EXPECT_GT(tick_of(after.payloads[i]), 97);
    }
    if (after.channels[i] == "SIM_EVENT") {
      semx::sim_event_t e{};
      ASSERT_GT(e.decode(after.payloads[i].data(), 0, static_cast<int>(after.payloads[i].size())), 0);
      EXPECT_NE(e.type, semx::sim_event_t::EPISODE_START);
    }
  }
  EXPECT_FALSE(before.channels.empty());
  std::remove(state.c_str());
}

// A restarted simulator in LOCKSTEP sends its last tick again and waits for every node's ack
// of it before it steps on.
TEST(SimulatorNode, ResumedLockstepResendsItsLastTickAndWaitsForTheAcks) {
  const std::string state = ::testing::TempDir() + "/sim_state_ls_" + std::to_string(getpid());
  SimulatorNodeOptions o = lockstep(0);
  o.state_path = state;
  run(100, nullptr, 40, o);
  o.resume = true;
  o.clock.lockstep_nodes = {"mapper"};
  o.clock.max_ticks = 100;
  o.clock.resend_after_s = 1.0;  // one resend in this test's 0.2 s
  SimulatorConfig cfg;
  Simulator sim(test::shipped("env1"), cfg);
  runtime::Node node(memq_node());
  std::vector<int64_t> ticks;
  node.subscribe<semx::clock_t>("SIM_CLOCK", [&](const semx::clock_t& m) { ticks.push_back(m.tick); });
  SimulatorNode sn(sim, node, o);
  EXPECT_EQ(sn.resumed_at(), 40);
  EXPECT_TRUE(sn.ready()) << "the nodes are running: no waiting for their NODE_STATUS";
  // The node resumed on the wall clock (steady_clock seconds): poll on it too.
  const double now =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  sn.poll(now);
  node.drain();
  sn.poll(now + 0.1);
  node.drain();
  EXPECT_EQ(ticks, std::vector<int64_t>{40}) << "tick 40 again, and nothing more without an ack";
  semx::ack_t ack{};
  ack.node = "mapper";
  ack.tick = 40;
  node.publish("SIM_ACK", ack);
  node.drain();
  sn.poll(now + 0.2);
  node.drain();
  EXPECT_EQ(ticks, (std::vector<int64_t>{40, 41}));
  std::remove(state.c_str());
}

TEST(SimulatorNode, SameSeedSameMessageStream) {
  const Captured a = run(40), b = run(40);
  ASSERT_EQ(a.channels, b.channels);
  // A tick names its publishers by their random sender ids (docs/runtime.md, "Lost messages"):
  // the same run has other ids, and everything else the same.
  const auto without_senders = [](const std::vector<uint8_t>& bytes) {
    semx::clock_t m{};
    EXPECT_EQ(m.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    std::fill(m.head_sender.begin(), m.head_sender.end(), 0);
    std::vector<uint8_t> out(static_cast<std::size_t>(m.getEncodedSize()));
    m.encode(out.data(), 0, static_cast<int>(out.size()));
    return out;
  };
  for (std::size_t i = 0; i < a.payloads.size(); ++i) {
    if (a.channels[i] == "NODE_STATUS") continue;  // wall-clock liveness fields
    if (a.channels[i] == "SIM_CLOCK") {
      EXPECT_EQ(without_senders(a.payloads[i]), without_senders(b.payloads[i])) << " #" << i;
      continue;
    }
    EXPECT_EQ(a.payloads[i], b.payloads[i]) << a.channels[i] << " #" << i;
  }
}

void announce(runtime::Node& node, const std::string& who,
              runtime::NodeState state = runtime::NodeState::kRunning) {
  semx::node_status_t st{};
  st.node = who;
  st.state = static_cast<int8_t>(state);
  node.publish("NODE_STATUS", st);
}

// The first tick (with the initial frame, which resent ticks do not repeat) waits until every
// registered node said it is running, or until the wait times out.
TEST(SimulatorNode, LockstepStartsOnceEveryRegisteredNodeIsRunning) {
  SimulatorConfig cfg;
  Simulator sim(test::shipped("env1"), cfg);
  for (const bool timeout : {false, true}) {
    runtime::Node node(memq_node());
    std::vector<std::string> seen;
    node.subscribe_raw("CAMERA_DEPTH|SIM_CLOCK|SIM_EVENT|ODOMETRY",
                       [&](const std::string& ch, const uint8_t*, std::size_t) { seen.push_back(ch); });
    auto options = lockstep(-1);
    options.clock.lockstep_nodes = {"mapper", "planner"};
    options.ready_timeout_s = 2.0;
    SimulatorNode sn(sim, node, options);
    double wall = 0;
    auto spin = [&](int n) {
      for (int i = 0; i < n; ++i) sn.poll(wall += 0.001);
      node.drain();
    };
    spin(5);
    announce(node, "mapper", runtime::NodeState::kStarting);  // not running yet
    announce(node, "viewer");                                 // not registered
    announce(node, "planner");
    spin(5);
    EXPECT_TRUE(seen.empty()) << "published " << seen.front() << " before the mapper ran";
    EXPECT_FALSE(sn.ready());
    if (timeout) {
      wall += 2.0;
    } else {
      announce(node, "mapper");
    }
    spin(5);
    EXPECT_TRUE(sn.ready());
    ASSERT_FALSE(seen.empty());
    // The initial state goes out with tick 0.
    EXPECT_NE(std::find(seen.begin(), seen.end(), "CAMERA_DEPTH"), seen.end());
    EXPECT_EQ(seen.back(), "SIM_CLOCK");
  }
}

TEST(SimulatorNode, LockstepWaitsForEveryRegisteredNodesAck) {
  SimulatorConfig cfg;
  Simulator sim(test::shipped("env1"), cfg);
  runtime::Node node(memq_node());
  std::vector<int64_t> ticks;
  node.subscribe<semx::clock_t>("SIM_CLOCK", [&](const semx::clock_t& c) { ticks.push_back(c.tick); });
  auto options = lockstep(-1);
  options.clock.lockstep_nodes = {"mapper", "planner"};
  options.clock.resend_after_s = 1e9;
  SimulatorNode sn(sim, node, options);
  auto ack = [&](const std::string& who, int64_t tick) {
    semx::ack_t a{};
    a.node = who;
    a.tick = tick;
    node.publish("SIM_ACK", a);
  };
  double wall = 0;
  announce(node, "mapper");
  announce(node, "planner");
  for (int i = 0; i < 5; ++i) sn.poll(wall += 0.001);
  node.drain();
  EXPECT_EQ(ticks, std::vector<int64_t>{0}) << "no tick 1 before the acks";
  ack("mapper", 0);
  for (int i = 0; i < 5; ++i) sn.poll(wall += 0.001);
  node.drain();
  EXPECT_EQ(ticks, std::vector<int64_t>{0}) << "one of two acks is not enough";
  ack("planner", 0);
  for (int i = 0; i < 5; ++i) sn.poll(wall += 0.001);
  node.drain();
  EXPECT_EQ(ticks, (std::vector<int64_t>{0, 1}));
}
