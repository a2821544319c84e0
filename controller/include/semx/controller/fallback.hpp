// The safe fallback: a B-spline that stays exactly on the polyline. Every waypoint gets three
// equal control points (the vehicle stops there) and the points between lie on the segment, so
// any four consecutive control points are collinear and the curve cannot cut a corner: it is
// as collision-free as the planner's path. Along each segment the control points follow a
// discrete trapezoid, so speed and acceleration stay within the limits given.
//
// A vehicle that moves when the fallback starts cannot be on the path at rest: the curve starts
// with its velocity, brakes straight along it at `max_acceleration`, and returns to the first
// segment at its point nearest the stop. Only that ray and that return leave the polyline.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "semx/controller/bspline.hpp"

namespace semx::controller {

struct FallbackSpline {
  PositionSpline spline;
  std::vector<double> point_times;  // when each polyline point is reached, s
};

// `points` must have no repeats; points[0] is where the vehicle is, moving at `start_velocity`;
// a single point gives a hover there.
FallbackSpline make_fallback_spline(const std::vector<Eigen::Vector3d>& points,
                                    const Eigen::Vector3d& start_velocity, double max_speed,
                                    double max_acceleration, double knot_interval);

// The polyline that fallback flies: points[0], where braking stops and where it returns to the
// first segment (when moving), then points[1...].
std::vector<Eigen::Vector3d> fallback_route(const std::vector<Eigen::Vector3d>& points,
                                            const Eigen::Vector3d& start_velocity, double max_acceleration,
                                            double knot_interval);

}  // namespace semx::controller
