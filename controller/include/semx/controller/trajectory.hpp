// A trajectory the controller flies: position and yaw as uniform cubic B-splines with the same
// knots, from start_utime. Yaw is unwrapped (continuous); commands wrap it.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semx/controller/bspline.hpp"

namespace semx::controller {

struct TrajectoryPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  double yaw = 0.0;       // rad, unwrapped
  double yaw_rate = 0.0;  // rad/s
};

struct Trajectory {
  int64_t plan_id = -1;
  int64_t start_utime = 0;
  bool optimized = false;  // false: the safe fallback (piecewise-linear path, lower speed)
  PositionSpline position;
  YawSpline yaw;

  bool empty() const { return position.empty(); }
  double duration() const { return position.duration(); }
  double knot_interval() const { return position.knot_interval(); }
  // Seconds since the start at message time `utime` (negative before the start).
  double time_at(int64_t utime) const { return 1e-6 * static_cast<double>(utime - start_utime); }

  // State at t seconds after the start; before 0 and after the end, the end states.
  TrajectoryPoint sample(double t) const {
    TrajectoryPoint p;
    p.position = position.evaluate(t, 0);
    p.velocity = position.evaluate(t, 1);
    p.acceleration = position.evaluate(t, 2);
    if (!yaw.empty()) {
      p.yaw = yaw.evaluate(t, 0)(0);
      p.yaw_rate = yaw.evaluate(t, 1)(0);
    }
    return p;
  }
  Eigen::Vector3d position_at(double t) const { return position.evaluate(t, 0); }
  Eigen::Vector3d end_position() const { return position.evaluate(duration(), 0); }
  double end_yaw() const { return yaw.empty() ? 0.0 : yaw.evaluate(duration(), 0)(0); }

  // Bounds over the whole trajectory from the control points (convex hull): what the limits
  // are checked against.
  double max_speed() const { return position.derivative_bound(1); }
  double max_acceleration() const { return position.derivative_bound(2); }
  double max_yaw_rate() const { return yaw.empty() ? 0.0 : yaw.derivative_bound(1); }
};

}  // namespace semx::controller
