// Time along a polyline: a trapezoidal speed profile per segment (accelerate, cruise,
// decelerate at max_acceleration), slowing at each corner to what a B-spline with knot interval
// dt can turn within the acceleration limit. The optimiser starts from control points sampled
// from it, and the yaw profile takes the times the waypoints are passed from it.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace semx::controller {

class TimedPolyline {
 public:
  // `start_speed` along the first segment (clamped to [0, max_speed]); stops at the last point.
  // `segment_speed`, when not empty (one per segment), lowers each segment's cruise speed further:
  // the generator slows only the stretch of a path where the full-speed curve failed.
  TimedPolyline(std::vector<Eigen::Vector3d> points, double start_speed, double max_speed,
                double max_acceleration, double knot_interval, const std::vector<double>& segment_speed = {});

  double duration() const {
    return segments_.empty() ? 0.0 : segments_.back().t_start + segments_.back().time;
  }
  // When each polyline point is passed (s): 0 for the first, duration() for the last.
  const std::vector<double>& point_times() const { return point_times_; }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  double length() const { return length_; }

  Eigen::Vector3d position(double t) const;
  double speed(double t) const;

  // The speed the profile allows at a corner turning by `angle` (rad): there the velocity control
  // points of a spline with knot interval dt change direction within one interval.
  static double corner_speed(double angle, double max_speed, double max_acceleration, double knot_interval);

 private:
  struct Segment {
    Eigen::Vector3d start, dir;
    double length = 0, v0 = 0, vp = 0, v1 = 0;  // entry, peak and exit speeds
    double t1 = 0, t2 = 0, t3 = 0;              // accelerate, cruise, decelerate durations
    double t_start = 0, time = 0;
  };
  double distance_in(const Segment& s, double tau) const;
  const Segment* segment_at(double t) const;

  std::vector<Eigen::Vector3d> points_;
  std::vector<Segment> segments_;
  std::vector<double> point_times_;
  double a_ = 1.0;
  double length_ = 0.0;
};

}  // namespace semx::controller
