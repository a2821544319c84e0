// Headings that keep the body's corners off the obstacles the path passes close to.
//
// The body is a square box; the clearance bounds assume a face toward the nearest obstacle, and a
// corner reaches √2 farther. Where the planner's path passes closer than a corner's reach (its
// doorway and passage nodes, 0.35 m from a jamb or a door leaf's edge in the ESDF), a body heading
// diagonally to that obstacle touches it: DEP, env3 seed 2, flew the fallback through such a node
// 0.35 m from a door leaf's edge heading -54°, and the corner reached 0.5 mm into the leaf. The
// camera loses little by turning at most 45° while it passes such a point.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "semx/controller/distance_field.hpp"

namespace semx::controller {

// For each waypoint but the first (the vehicle, whose heading is what it is) whose distance is
// below `within` and where the nearest obstacle's direction is known (|∇distance| above the
// ridge threshold), turns yaws[k] by at most ±45° so that a face of the body looks along that
// direction. yaws stay unwrapped (each moves by the smallest turn). `within` <= 0: no change.
// Returns how many headings were turned.
int square_headings_near_obstacles(const std::vector<Eigen::Vector3d>& polyline, std::vector<double>& yaws,
                                   const DistanceField& field, double within);

// An optimised curve cuts the path's corners, so it may pass an obstacle closer than a corner's
// reach where no path point does, heading diagonally to it: the turned-body rule then sent the
// whole path to the fallback, which stops at every waypoint at half speed (env3, semantic-dep,
// seed 8: 8 such fallbacks in its first 200 s, 85 % only at 168 s). This holds the heading target
// square to the obstacle around the failing instant instead: knots (t - hold, face) and
// (t + hold, face) of the piecewise-linear heading target (times, yaws; yaw_profile.hpp) replace
// the knots between them, `face` the turn of at most 45° from `yaw_at_t` that makes a face of the
// body look along `gradient`. The first and last knots (the vehicle's heading, the goal's) are
// kept. Returns false when the obstacle's direction is unknown (|gradient_xy| at most the ridge
// threshold) or t is not inside the target.
bool hold_heading_square_at(std::vector<double>& times, std::vector<double>& yaws, double t, double yaw_at_t,
                            const Eigen::Vector3d& gradient, double hold);

}  // namespace semx::controller
