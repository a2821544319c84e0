#include "semx/controller/controller_config.hpp"

#include <string>

namespace semx::controller {

void load(runtime::ConfigMap& m, ControllerConfig& c) {
  m.get("rate_hz", c.rate_hz, 1.0, 1000.0);
  m.get("status_rate_hz", c.status_rate_hz, 0.1, 1000.0);

  auto l = m.child("limits");
  l.get("max_velocity", c.limits.max_velocity, 0.05, 20.0);
  l.get("max_acceleration", c.limits.max_acceleration, 0.05, 50.0);
  l.get("max_yaw_rate", c.limits.max_yaw_rate, 0.01, 20.0);

  auto cl = m.child("clearance");
  cl.get("half_size", c.clearance.half_size, 0.0, 5.0);
  cl.get("margin", c.clearance.margin, 0.0, 5.0);
  cl.get("brake_margin", c.clearance.brake_margin, 0.0, 5.0);
  cl.get("half_height", c.clearance.half_height, 0.0, 5.0);
  cl.get("footprint_margin", c.clearance.footprint_margin, 0.0, 5.0);
  cl.get("turned_body", c.clearance.turned_body);
  cl.get("square_headings", c.clearance.square_headings);
  cl.get("heading_repairs", c.clearance.heading_repairs, 0, 100);
  cl.get("heading_hold", c.clearance.heading_hold, 0.01, 10.0);
  cl.get("join_holds", c.clearance.join_holds);
  cl.get("square_fallback", c.clearance.square_fallback);
  cl.get("check_spacing", c.clearance.check_spacing, 0.001, 0.5);
  cl.get("allow_escape", c.clearance.allow_escape);
  std::string outside = c.clearance.outside_is_obstacle ? "obstacle" : "free";
  cl.get_choice("outside_window", outside, {"free", "obstacle"});
  c.clearance.outside_is_obstacle = outside == "obstacle";
  if (c.clearance.brake_margin > c.clearance.margin) {
    cl.fail("brake_margin", "must not exceed margin (a fresh trajectory would brake at once)");
  }

  auto t = m.child("trajectory");
  t.get("knot_interval", c.trajectory.knot_interval, 0.02, 2.0);
  t.get("fallback_speed_factor", c.trajectory.fallback_speed_factor, 0.05, 1.0);
  t.get("max_deviation", c.trajectory.max_deviation, 0.0, 100.0);
  t.get("slow_zone_radius", c.trajectory.slow_zone_radius, 0.0, 100.0);
  t.get("slow_zone_tries", c.trajectory.slow_zone_tries, 0, 20);

  auto o = m.child("optimizer");
  o.get("max_iterations", c.optimizer.max_iterations, 0, 100000);
  o.get("weight_smoothness", c.optimizer.weight_smoothness, 0.0, 1e6);
  o.get("weight_clearance", c.optimizer.weight_clearance, 0.0, 1e6);
  o.get("weight_feasibility", c.optimizer.weight_feasibility, 0.0, 1e6);
  o.get("target_margin", c.optimizer.target_margin, 0.0, 2.0);
  o.get("weight_fidelity", c.optimizer.weight_fidelity, 0.0, 1e6);
  o.get("fidelity_tolerance", c.optimizer.fidelity_tolerance, 0.0, 10.0);
  o.get("samples_per_segment", c.optimizer.samples_per_segment, 1, 20);

  auto p = m.child("path");
  p.get("max_waypoints", c.path.max_waypoints, 1, 100000);
  p.get("max_segment_length", c.path.max_segment_length, 0.01, 1000.0);
  p.get("max_start_offset", c.path.max_start_offset, 0.0, 1000.0);
  p.get("max_age", c.path.max_age, 0.0, 3600.0);

  auto k = m.child("tracking");
  k.get("position_gain", c.tracking.position_gain, 0.0, 100.0);
  k.get("velocity_gain", c.tracking.velocity_gain, 0.0, 100.0);
  k.get("accel_feedforward", c.tracking.accel_feedforward, 0.0, 10.0);
  k.get("yaw_feedforward", c.tracking.yaw_feedforward, 0.0, 10.0);
  k.get("max_command_speed", c.tracking.max_command_speed, 0.01, 50.0);
  k.get("max_command_speed_z", c.tracking.max_command_speed_z, 0.01, 50.0);

  auto s = m.child("safety");
  s.get("check_horizon", c.safety.check_horizon, 0.0, 3600.0);
  s.get("max_odometry_age", c.safety.max_odometry_age, 0.0, 3600.0);
  s.get("max_esdf_age", c.safety.max_esdf_age, 0.0, 3600.0);
  s.get("max_tracking_error", c.safety.max_tracking_error, 0.0, 100.0);
}

}  // namespace semx::controller
