// The camera heading along a trajectory: from the start yaw, turn toward each waypoint's yaw
// while flying the segment that leads to it (linearly in time), never faster than the yaw-rate
// limit. Yaw control points share the position spline's knots, so a yaw-rate limit on their
// differences bounds the yaw rate everywhere (convex hull), like velocity.
#pragma once

#include <vector>

#include "semx/controller/trajectory.hpp"

namespace semx::controller {

// Fills trajectory.yaw. `times[k]` is when waypoint k is reached (s, times[0] = 0) and
// `yaws[k]` its unwrapped heading (yaws[0] = the vehicle's). When the last heading is not
// reached by the end of the position spline, the trajectory is extended by hovering at its end
// until it is, so the camera always ends up where the planner asked.
void add_yaw_profile(Trajectory& trajectory, const std::vector<double>& times,
                     const std::vector<double>& yaws, double max_yaw_rate);

}  // namespace semx::controller
