#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "semx/simulator/simulator.hpp"
#include "test_util.hpp"

namespace semx::simulator {
namespace {

SimulatorConfig small_camera_config() {
  SimulatorConfig c;
  c.camera.width = 160;
  c.camera.height = 120;
  c.camera.fx = c.camera.fy = 80;
  c.camera.cx = 80;
  c.camera.cy = 60;
  return c;
}

TEST(Simulator, SensorsFallDueAtTheirRates) {
  Simulator sim(test::shipped("env1"), small_camera_config());
  int imu = 0, odom = 0, cam = 0;
  int64_t last_cam = 0;
  std::vector<int64_t> cam_times;
  while (sim.time_us() < 2000000) {
    const StepResult r = sim.step();
    EXPECT_EQ(r.utime, sim.time_us());
    if (r.imu) {
      ++imu;
      EXPECT_EQ(r.imu->utime % 5000, 0);
    }
    if (r.odometry) {
      ++odom;
      EXPECT_EQ(r.odometry->utime % 10000, 0);
    }
    if (r.camera_due) {
      ++cam;
      cam_times.push_back(r.utime);
      last_cam = r.utime;
    }
  }
  EXPECT_EQ(imu, 400);
  EXPECT_EQ(odom, 200);
  EXPECT_EQ(cam, 60);
  EXPECT_EQ(last_cam, 2000000);
  // Each frame at the first step not before k/30 s: at most one step late.
  for (size_t k = 0; k < cam_times.size(); ++k) {
    const double nominal = (k + 1) * 1e6 / 30.0;
    EXPECT_GE(cam_times[k], nominal - 0.5);
    EXPECT_LT(cam_times[k], nominal + 1000);
  }
}

TEST(Simulator, CameraFrameCarriesPoseAndTime) {
  Simulator sim(test::shipped("env1"), small_camera_config());
  sim.command(ControlCommand::velocity({0.3, 0, 0}, 0.2));
  StepResult r;
  do r = sim.step();
  while (!r.camera_due);
  CameraFrame f;
  sim.render_camera(f);
  EXPECT_EQ(f.utime, r.utime);
  EXPECT_EQ(f.frame_id, 1);
  EXPECT_TRUE(f.pose.isApprox(sim.vehicle().state().camera_pose()));
  // The optical axis is the body's x axis.
  const double yaw = sim.vehicle().state().yaw;
  EXPECT_NEAR(f.pose.linear().col(2).dot(Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0)), 1.0, 1e-12);
  EXPECT_EQ(f.depth.width, 160);
  EXPECT_EQ(f.rgb.height, 120);
}

// Everything a node would publish, as bytes, for comparing two runs.
struct Recorder {
  std::string bytes;
  template <class T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_vec(const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) put(v[k]);
  }
};

std::string run(uint64_t seed) {
  SimulatorConfig c = small_camera_config();
  c.seed = seed;
  c.depth_noise.enabled = true;
  c.detection_noise.enabled = true;
  c.imu.accel_bias_random_walk = 1e-3;
  Simulator sim(test::shipped("env2"), c);
  Recorder rec;
  CameraFrame f;
  for (int i = 0; i < 3000; ++i) {
    if (i % 20 == 0) {
      const double t = i * 1e-3;
      sim.command(
          ControlCommand::velocity({0.6 * std::cos(t), 0.6 * std::sin(0.7 * t), 0.1 * std::sin(t)}, 0.4));
    }
    const StepResult r = sim.step();
    if (r.imu) {
      rec.put(r.imu->utime);
      rec.put_vec(r.imu->linear_acceleration);
      rec.put_vec(r.imu->angular_velocity);
    }
    if (r.odometry) {
      rec.put_vec(r.odometry->position);
      rec.put_vec(r.odometry->velocity);
      rec.put(r.odometry->orientation.w());
      rec.put(r.odometry->orientation.z());
    }
    if (r.camera_due) {
      sim.render_camera(f);
      rec.bytes.append(reinterpret_cast<const char*>(f.depth.data.data()), f.depth.data.size() * 2);
      rec.bytes.append(reinterpret_cast<const char*>(f.class_label.data.data()),
                       f.class_label.data.size() * 2);
      rec.bytes.append(reinterpret_cast<const char*>(f.instance_label.data.data()),
                       f.instance_label.data.size() * 2);
      rec.bytes.append(reinterpret_cast<const char*>(f.rgb.data.data()), f.rgb.data.size() * 3);
    }
  }
  return rec.bytes;
}

TEST(Simulator, SameSeedSameOutputsBitForBit) {
  const std::string a = run(4), b = run(4), c = run(5);
  EXPECT_GT(a.size(), 100000u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(Simulator, CommandTimeoutHoldsPosition) {
  SimulatorConfig c = small_camera_config();
  c.command_timeout_us = 200000;
  Simulator sim(test::shipped("env3"), c);
  sim.command(ControlCommand::velocity({0.8, 0, 0}));
  int timeouts = 0;
  int64_t timeout_at = 0;
  for (int i = 0; i < 3000; ++i) {
    const StepResult r = sim.step();
    if (r.command_timed_out) {
      ++timeouts;
      timeout_at = r.utime;
    }
  }
  EXPECT_EQ(timeouts, 1);
  EXPECT_EQ(timeout_at, 201000);
  EXPECT_EQ(sim.command_timeouts(), 1);
  EXPECT_LT(sim.vehicle().state().velocity.norm(), 0.05);
  EXPECT_EQ(sim.vehicle().active_command().mode, ControlCommand::kHold);
}

TEST(Simulator, ReportsCollisionEvents) {
  Simulator sim(test::shipped("env1"), small_camera_config());
  // From the start (2, 3, 1.2) straight up into the ceiling at 2.7 m.
  int events = 0;
  for (int i = 0; i < 4000; ++i) {
    if (i % 100 == 0) sim.command(ControlCommand::velocity({0, 0, 1.0}));
    const StepResult r = sim.step();
    if (r.collision) {
      ++events;
      EXPECT_EQ(sim.world().solids[r.collision->solid].cls, SemanticClass::kCeiling);
      EXPECT_EQ(r.collision->count, events);
      EXPECT_NEAR(r.collision->position.z(), 2.7 - 0.15, 0.002);
    }
  }
  EXPECT_EQ(events, 1);
  EXPECT_EQ(sim.vehicle().collisions(), 1);
}

TEST(SimulatorConfigFile, StrictLoading) {
  auto m = runtime::ConfigMap::from_string(
      "seed: 9\ncamera: {width: 320, height: 240, fx: 160, fy: 160}\nvehicle: {max_speed_xy: 2.0}\n"
      "depth_noise: {enabled: true}\n",
      "sim.yaml");
  SimulatorConfig c;
  load(m, c);
  m.finish();
  EXPECT_EQ(c.seed, 9u);
  EXPECT_EQ(c.camera.width, 320);
  EXPECT_DOUBLE_EQ(c.camera.cx, 160);  // follows the size when not given
  EXPECT_DOUBLE_EQ(c.vehicle.max_speed_xy, 2.0);
  EXPECT_TRUE(c.depth_noise.enabled);
  auto bad = runtime::ConfigMap::from_string("vehicle: {max_sped_xy: 2.0}\n", "sim.yaml");
  SimulatorConfig d;
  load(bad, d);
  EXPECT_THROW(bad.finish(), runtime::ConfigError);
  auto range = runtime::ConfigMap::from_string("camera: {min_range: 6.0}\n", "sim.yaml");
  EXPECT_THROW(load(range, d), runtime::ConfigError);
}

}  // namespace
}  // namespace semx::simulator
