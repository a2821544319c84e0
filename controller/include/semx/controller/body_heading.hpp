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

}  // namespace semx::controller
