// A path from the planner (PLAN_PATH as plain data) and the checks that reject bad ones.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/controller/controller_config.hpp"

namespace semx::controller {

struct Path {
  int64_t utime = 0;
  int64_t plan_id = 0;
  std::vector<Eigen::Vector3d> waypoints;  // m, world frame
  std::vector<double> yaws;                // rad, heading wanted at each waypoint
  double max_speed = 0.0;                  // m/s, 0 = the configured limit
};

// Why the path cannot be flown regardless of where the vehicle is (empty, non-finite values,
// too many waypoints, jumps longer than max_segment_length, negative speed), or "" when usable.
std::string check_path(const Path& path, const PathConfig& config);

// As check_path(), plus the first waypoint's distance from the vehicle (max_start_offset).
std::string check_path_start(const Path& path, const Eigen::Vector3d& vehicle, const PathConfig& config);

// The polyline to fly: the vehicle's position in place of the first waypoint (the planner
// planned from where the vehicle was a moment ago), then the other waypoints with repeats
// (closer than 1 mm) dropped; a one-waypoint path is flown from the vehicle to it. `yaws` gets
// the matching headings, unwrapped along the way (shortest turns), `yaws[0]` = `vehicle_yaw`.
std::vector<Eigen::Vector3d> flight_polyline(const Path& path, const Eigen::Vector3d& vehicle,
                                             double vehicle_yaw, std::vector<double>* yaws);

}  // namespace semx::controller
