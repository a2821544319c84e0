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

// Where a curve broke the turned-body rule: when, the nearest obstacle's direction (unit, the
// ESDF gradient) and the farthest the body may reach toward it there
// (ClearanceReport::reach_allowed).
struct ReachLimit {
  double time = 0.0;  // s
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double allowed = 0.0;  // m
};

// A heading that turns at a constant rate: yaw + rate·(t - time).
struct HeadingRamp {
  double time = 0.0;
  double yaw = 0.0;
  double rate = 0.0;  // rad/s
  double at(double t) const { return yaw + rate * (t - time); }
};

// The ramp through `limits` (a heading within 45° of `yaw` at the first limit's time, the body's
// reach repeating every quarter turn, and a rate of at most `max_rate`) that leaves the body the
// most room (the largest smallest allowed - footprint_reach); of equally good ones the steadiest
// and nearest to `yaw`. One limit: a face square to its obstacle. A doorway's two jamb ends, passed
// a few centimetres and hundredths of a second apart, want different squares (env3, a door of the
// east rooms: 173° and 23°): no square heading passes both, a heading between them does, and a
// third limit a few tenths of a second on (the far side's jamb, -24°) a heading that turns.
HeadingRamp heading_for_limits(double yaw, const std::vector<ReachLimit>& limits, double max_rate,
                               double half_xy, double half_z);

// An optimised curve cuts the path's corners, so it may pass an obstacle closer than a corner's
// reach where no path point does, heading diagonally to it: the turned-body rule then sent the
// whole path to the fallback, which stops at every waypoint at half speed (env3, semantic-dep,
// seed 8: 8 such fallbacks in its first 200 s, 85 % only at 168 s). The generator holds the
// heading target instead (TrajectoryGenerator, clearance.heading_repairs): knots
// (inner_a - hold, ramp) and (inner_b + hold, ramp) of the piecewise-linear heading target (times,
// yaws; yaw_profile.hpp) replace the knots between them, [inner_a, inner_b] the failing instants.
// Near the first and last knots the hold ends halfway to them, so that the vehicle's heading and
// the goal's stay. Returns false, changing nothing, when the instants are not inside the target.
bool hold_heading(std::vector<double>& times, std::vector<double>& yaws, double inner_a, double inner_b,
                  double hold, const HeadingRamp& ramp);

}  // namespace semx::controller
