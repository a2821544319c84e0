// The safe fallback: a B-spline that stays exactly on the polyline. Every waypoint gets three
// equal control points (the vehicle stops there) and the points between lie on the segment, so
// any four consecutive control points are collinear and the curve cannot cut a corner: it is
// as collision-free as the planner's path. Along each segment the control points follow a
// discrete trapezoid, so speed and acceleration stay within the limits given.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "semx/controller/bspline.hpp"

namespace semx::controller {

struct FallbackSpline {
  PositionSpline spline;
  std::vector<double> point_times;  // when each polyline point is reached, s
};

// `points` must have no repeats; a single point gives a hover there.
FallbackSpline make_fallback_spline(const std::vector<Eigen::Vector3d>& points, double max_speed,
                                    double max_acceleration, double knot_interval);

}  // namespace semx::controller
