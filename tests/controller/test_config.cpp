// The controller's configuration: defaults, the documented YAML file, strictness.
#include <gtest/gtest.h>

#include <filesystem>

#include "semx/controller/controller_config.hpp"

using namespace semx::controller;
using semx::runtime::ConfigError;
using semx::runtime::load_config;

TEST(ControllerConfig, TheShippedYamlIsExactlyTheDefaults) {
  const ControllerConfig d;
  const auto f =
      load_config<ControllerConfig>(std::string(SEMX_SOURCE_DIR) + "/controller/config/controller.yaml");
#define SAME(field) EXPECT_EQ(f.field, d.field) << #field
  SAME(rate_hz);
  SAME(status_rate_hz);
  SAME(limits.max_velocity);
  SAME(limits.max_acceleration);
  SAME(limits.max_yaw_rate);
  SAME(clearance.half_size);
  SAME(clearance.margin);
  SAME(clearance.brake_margin);
  SAME(clearance.check_spacing);
  SAME(clearance.allow_escape);
  SAME(clearance.outside_is_obstacle);
  SAME(trajectory.knot_interval);
  SAME(trajectory.fallback_speed_factor);
  SAME(trajectory.slow_zone_radius);
  SAME(trajectory.slow_zone_tries);
  SAME(clearance.half_height);
  SAME(clearance.footprint_margin);
  SAME(clearance.turned_body);
  SAME(clearance.heading_repairs);
  SAME(clearance.heading_hold);
  SAME(clearance.join_holds);
  SAME(trajectory.max_deviation);
  SAME(optimizer.max_iterations);
  SAME(optimizer.weight_smoothness);
  SAME(optimizer.weight_clearance);
  SAME(optimizer.weight_feasibility);
  SAME(optimizer.target_margin);
  SAME(optimizer.weight_fidelity);
  SAME(optimizer.fidelity_tolerance);
  SAME(optimizer.samples_per_segment);
  SAME(path.max_waypoints);
  SAME(path.max_segment_length);
  SAME(path.max_start_offset);
  SAME(path.max_age);
  SAME(tracking.position_gain);
  SAME(tracking.velocity_gain);
  SAME(tracking.accel_feedforward);
  SAME(tracking.yaw_feedforward);
  SAME(tracking.max_command_speed);
  SAME(tracking.max_command_speed_z);
  SAME(safety.check_horizon);
  SAME(safety.max_odometry_age);
  SAME(safety.max_esdf_age);
#undef SAME
}

TEST(ControllerConfig, TheShippedAblationsLoad) {
  const std::string dir = std::string(SEMX_SOURCE_DIR) + "/controller/config/ablations/";
  EXPECT_EQ(load_config<ControllerConfig>(dir + "no_fidelity.yaml").optimizer.weight_fidelity, 0.0);
  EXPECT_FALSE(load_config<ControllerConfig>(dir + "no_join_holds.yaml").clearance.join_holds);
  // Every file there is one a bench can be given (`--arg controller_config=...`).
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    EXPECT_NO_THROW(load_config<ControllerConfig>(entry.path().string())) << entry.path();
  }
  EXPECT_GE(files, 3);
}

TEST(ControllerConfig, OverridesAndErrors) {
  const auto c = load_config<ControllerConfig>(
      "", {"limits.max_velocity=0.7", "clearance.outside_window=obstacle", "optimizer.max_iterations=0"});
  EXPECT_EQ(c.limits.max_velocity, 0.7);
  EXPECT_TRUE(c.clearance.outside_is_obstacle);
  EXPECT_EQ(c.optimizer.max_iterations, 0);
  EXPECT_THROW(load_config<ControllerConfig>("", {"limits.max_velocty=0.7"}), ConfigError);
  EXPECT_THROW(load_config<ControllerConfig>("", {"limits.max_velocity=-1"}), ConfigError);
  EXPECT_THROW(load_config<ControllerConfig>("", {"clearance.outside_window=maybe"}), ConfigError);
  EXPECT_THROW(load_config<ControllerConfig>("", {"clearance.brake_margin=0.2"}), ConfigError);
}
