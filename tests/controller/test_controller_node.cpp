// The controller node over memq:// (one process): subscriptions with content checks, the
// control step on SIM_CLOCK ticks, and what it publishes.
#include <gtest/gtest.h>

#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>

#include "controller_messages.hpp"
#include "controller_node.hpp"
#include "node_messages.hpp"
#include "semx/fixtures/synthetic_scene.hpp"
#include "semx/runtime/channels.hpp"

using namespace semx::controller;
using namespace semx::controller::test;
namespace ch = semx::channels;

namespace {

semx::runtime::NodeOptions memq() {
  semx::runtime::NodeOptions o;
  o.name = "controller";
  o.lcm_url = "memq://";
  o.status_period_s = 1000;
  o.quiet = true;
  return o;
}

semx::clock_t clock_message(int64_t tick, int64_t utime) {
  semx::clock_t c{};
  c.tick = tick;
  c.utime = utime;
  c.mode = semx::clock_t::LOCKSTEP;
  c.period_us = 10'000;
  return c;
}

struct Harness {
  ControllerNode cn{memq(), ControllerConfig()};
  std::vector<semx::control_cmd_t> commands;
  std::vector<semx::trajectory_t> trajectories;
  std::vector<semx::controller_status_t> statuses;
  int64_t tick = 0, utime = 0;

  Harness() {
    auto& n = cn.node();
    n.subscribe<semx::control_cmd_t>(ch::CONTROL_CMD,
                                     [this](const semx::control_cmd_t& m) { commands.push_back(m); });
    n.subscribe<semx::trajectory_t>(ch::TRAJECTORY,
                                    [this](const semx::trajectory_t& m) { trajectories.push_back(m); });
    n.subscribe<semx::controller_status_t>(
        ch::CONTROLLER_STATUS, [this](const semx::controller_status_t& m) { statuses.push_back(m); });
  }
  template <class T>
  void send(const char* channel, const T& m) {
    cn.node().publish(channel, m);
    cn.node().drain();
  }
  void advance(int ticks, int64_t period_us = 10'000) {
    for (int i = 0; i < ticks; ++i) {
      ++tick;
      utime += period_us;
      send(ch::SIM_CLOCK, clock_message(tick, utime));
    }
    cn.node().drain();
  }
  int64_t malformed(const char* channel) const {
    const auto& in = cn.node().incoming();
    const auto it = in.find(channel);
    return it == in.end() ? 0 : it->second.malformed;
  }
};

}  // namespace

TEST(ControllerNode, FliesAPathEndToEnd) {
  Harness h;
  const SyntheticScene scene = make_cluttered_scene(5);
  h.utime = 1'000'000;
  h.send(ch::ESDF_LOCAL, esdf_message(scene.field, h.utime));
  h.send(ch::ODOMETRY, odometry(scene.path.front(), h.utime));
  h.advance(1);
  ASSERT_FALSE(h.statuses.empty());
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::IDLE);
  EXPECT_EQ(h.commands.back().mode, semx::control_cmd_t::HOLD);

  h.send(ch::PLAN_PATH, path_message(scene.path, 7, h.utime));
  h.send(ch::ODOMETRY, odometry(scene.path.front(), h.utime + 10'000));
  h.advance(1);
  ASSERT_EQ(h.trajectories.size(), 1u);
  const semx::trajectory_t& t = h.trajectories[0];
  EXPECT_EQ(t.plan_id, 7);
  EXPECT_EQ(t.degree, 3);
  EXPECT_EQ(t.start_utime, h.utime);
  EXPECT_TRUE(t.optimized);
  EXPECT_EQ(t.num_control_points, static_cast<int32_t>(t.control_points.size()));
  // What was published is what is flown.
  const Trajectory back = to_trajectory(t);
  const Trajectory* flown = h.cn.controller().trajectory();
  ASSERT_NE(flown, nullptr);
  EXPECT_DOUBLE_EQ(back.duration(), flown->duration());
  EXPECT_LT((back.position_at(1.3) - flown->position_at(1.3)).norm(), 1e-12);
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::TRACKING);
  EXPECT_EQ(h.statuses.back().plan_id, 7);
  EXPECT_EQ(h.commands.back().mode, semx::control_cmd_t::VELOCITY);
  EXPECT_EQ(h.commands.back().yaw_mode, semx::control_cmd_t::YAW_ANGLE);
  EXPECT_EQ(h.commands.back().utime, h.utime);

  // One command per 10 ms tick, status at 10 Hz of message time (plus changes).
  const std::size_t cmds = h.commands.size(), stats = h.statuses.size();
  for (int i = 0; i < 100; ++i) {
    h.send(ch::ODOMETRY, odometry(scene.path.front(), h.utime + 10'000));
    if (i % 3 == 0) h.send(ch::ESDF_LOCAL, esdf_message(scene.field, h.utime + 10'000));
    h.advance(1);
  }
  EXPECT_EQ(h.commands.size() - cmds, 100u);
  EXPECT_EQ(h.statuses.size() - stats, 10u);
  EXPECT_EQ(h.trajectories.size(), 1u);
  EXPECT_EQ(h.cn.node().state(), semx::runtime::NodeState::kRunning);
}

TEST(ControllerNode, StopsWhenInputsGoStaleAndReportsDegraded) {
  Harness h;
  h.advance(5);
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::STALE_INPUT);
  EXPECT_EQ(h.statuses.back().reason, "no odometry yet");
  EXPECT_EQ(h.commands.back().mode, semx::control_cmd_t::HOLD);
  EXPECT_EQ(h.cn.node().state(), semx::runtime::NodeState::kDegraded);
}

TEST(ControllerNode, InconsistentOrNonFiniteMessagesAreMalformedAndNeverReachTheLogic) {
  Harness h;
  const SyntheticScene scene = make_cluttered_scene(6);
  h.utime = 1'000'000;
  auto esdf = esdf_message(scene.field, h.utime);
  auto bad_cells = esdf;
  bad_cells.nx -= 1;  // num_cells no longer nx*ny*nz
  h.send(ch::ESDF_LOCAL, bad_cells);
  auto nan_value = esdf;
  nan_value.distance[17] = NAN;
  h.send(ch::ESDF_LOCAL, nan_value);
  auto inf_value = esdf;
  inf_value.distance.back() = -INFINITY;
  h.send(ch::ESDF_LOCAL, inf_value);
  auto zero_res = esdf;
  zero_res.resolution = 0;
  h.send(ch::ESDF_LOCAL, zero_res);
  EXPECT_EQ(h.malformed(ch::ESDF_LOCAL), 4);

  auto nan_odom = odometry({0, 0, 1}, h.utime);
  nan_odom.velocity[1] = NAN;
  h.send(ch::ODOMETRY, nan_odom);
  auto bad_quat = odometry({0, 0, 1}, h.utime);
  bad_quat.orientation[0] = 0.5;
  h.send(ch::ODOMETRY, bad_quat);
  EXPECT_EQ(h.malformed(ch::ODOMETRY), 2);

  h.advance(1);
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::STALE_INPUT);
  EXPECT_EQ(h.statuses.back().reason, "no odometry yet");

  // A path's content is the controller's to judge, so the planner hears REJECTED.
  h.send(ch::ESDF_LOCAL, esdf);
  h.send(ch::ODOMETRY, odometry(scene.path.front(), h.utime + 10'000));
  auto nan_path = path_message(scene.path, 3, h.utime);
  nan_path.waypoints[2][1] = NAN;
  h.send(ch::PLAN_PATH, nan_path);
  EXPECT_EQ(h.malformed(ch::PLAN_PATH), 0);
  h.advance(1);
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::REJECTED);
  EXPECT_EQ(h.statuses.back().plan_id, 3);
  EXPECT_EQ(h.cn.controller().counters().rejected, 1);
}

TEST(ControllerNode, RunsAtItsRateWhateverTheClockPeriod) {
  Harness h;
  h.advance(100, 1'000);  // 1 ms ticks for 0.1 s: 10 steps at 100 Hz
  EXPECT_EQ(h.commands.size(), 10u);
}

// In LOCKSTEP the controller promises quiet until its next control step, so the clock waits for
// it only on the ticks it steps on; at the tick rate the promise is no wider than one tick.
TEST(ControllerNode, PromisesQuietUntilItsNextControlStep) {
  for (double rate : {50.0, 100.0}) {
    SCOPED_TRACE(rate);
    semx::runtime::NodeOptions o = memq();
    o.lockstep = true;
    ControllerConfig c;
    c.rate_hz = rate;
    ControllerNode cn(o, c);
    std::vector<semx::ack_t> acks;
    std::vector<int64_t> command_times;
    cn.node().subscribe<semx::ack_t>(ch::SIM_ACK, [&](const semx::ack_t& a) { acks.push_back(a); });
    cn.node().subscribe<semx::control_cmd_t>(
        ch::CONTROL_CMD, [&](const semx::control_cmd_t& m) { command_times.push_back(m.utime); });
    int64_t promised = 0;  // the last promise heard before each command
    std::vector<int64_t> promise_at_command;
    for (int64_t tick = 0; tick <= 20; ++tick) {
      const size_t before = command_times.size();
      cn.node().publish(ch::SIM_CLOCK, clock_message(tick, tick * 10'000));
      cn.node().drain();
      cn.node().drain();
      if (command_times.size() > before) promise_at_command.push_back(promised);
      if (!acks.empty()) promised = acks.back().quiet_until;
    }
    const size_t steps = rate == 50.0 ? 11u : 21u;
    ASSERT_EQ(command_times.size(), steps);
    for (size_t i = 0; i < command_times.size(); ++i) {
      EXPECT_EQ(command_times[i], static_cast<int64_t>(i) * (rate == 50.0 ? 20'000 : 10'000));
      EXPECT_LE(promise_at_command[i], command_times[i]) << "a command inside the promise";
    }
    ASSERT_FALSE(acks.empty());
    if (rate == 50.0) {
      EXPECT_EQ(acks.front().quiet_until, 19'999);  // after the step at 0: the next at 20 ms
    } else {
      for (const semx::ack_t& a : acks) EXPECT_LT(a.quiet_until, a.utime + 10'000);
    }
  }
}

TEST(ControllerNode, AClockRestartIsANewEpisode) {
  Harness h;
  const SyntheticScene scene = make_cluttered_scene(8);
  h.utime = 5'000'000;
  h.send(ch::ESDF_LOCAL, esdf_message(scene.field, h.utime));
  h.send(ch::ODOMETRY, odometry(scene.path.front(), h.utime));
  h.send(ch::PLAN_PATH, path_message(scene.path, 1, h.utime));
  h.advance(1);
  ASSERT_NE(h.cn.controller().trajectory(), nullptr);
  h.tick = -1;
  h.utime = -10'000;
  h.advance(1);  // tick 0 at t = 0
  EXPECT_EQ(h.cn.controller().trajectory(), nullptr);
  EXPECT_EQ(h.cn.controller().counters().trajectories, 0);
  EXPECT_EQ(h.statuses.back().state, semx::controller_status_t::STALE_INPUT);
}

TEST(MessageAdapter, OdometryYawAndCommandWrapping) {
  semx::odometry_t m = odometry({1, 2, 3}, 42);
  const double yaw = 2.5;
  m.orientation[0] = std::cos(yaw / 2);
  m.orientation[3] = std::sin(yaw / 2);
  const VehicleState s = to_vehicle_state(m);
  EXPECT_NEAR(s.yaw, yaw, 1e-12);
  EXPECT_EQ(s.utime, 42);
  Command c;
  c.mode = Command::Mode::kVelocity;
  c.velocity = Eigen::Vector3d(0.1, 0.2, 0.3);
  c.yaw = 4.0;
  const semx::control_cmd_t cm = to_message(c, 9);
  EXPECT_EQ(cm.mode, semx::control_cmd_t::VELOCITY);
  EXPECT_NEAR(cm.yaw, 4.0 - 2 * M_PI, 1e-12);
  EXPECT_EQ(cm.setpoint[2], 0.3);
  c.mode = Command::Mode::kHold;
  EXPECT_EQ(to_message(c, 9).setpoint[0], 0.0);
}
