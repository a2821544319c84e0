#include "semx/controller/path.hpp"

#include <cmath>

#include "semx/core/angles.hpp"
#include "semx/core/text.hpp"

namespace semx::controller {

std::string check_path(const Path& path, const PathConfig& config) {
  const std::size_t n = path.waypoints.size();
  if (n == 0) return "empty path";
  if (path.yaws.size() != n) return "yaws and waypoints differ in number";
  if (static_cast<int64_t>(n) > config.max_waypoints) {
    return std::to_string(n) + " waypoints (max " + std::to_string(config.max_waypoints) + ")";
  }
  if (!std::isfinite(path.max_speed) || path.max_speed < 0)
    return "max_speed " + core::short_number(path.max_speed);
  for (std::size_t i = 0; i < n; ++i) {
    if (!path.waypoints[i].allFinite()) return "waypoint " + std::to_string(i) + " is not finite";
    if (!std::isfinite(path.yaws[i])) return "yaw " + std::to_string(i) + " is not finite";
  }
  for (std::size_t i = 1; i < n; ++i) {
    const double d = (path.waypoints[i] - path.waypoints[i - 1]).norm();
    if (d > config.max_segment_length) {
      return "jump of " + core::short_number(d) + " m between waypoints " + std::to_string(i - 1) + " and " +
             std::to_string(i) + " (max " + core::short_number(config.max_segment_length) + " m)";
    }
  }
  return "";
}

std::string check_path_start(const Path& path, const Eigen::Vector3d& vehicle, const PathConfig& config) {
  std::string why = check_path(path, config);
  if (!why.empty()) return why;
  const double d = (path.waypoints.front() - vehicle).norm();
  if (!(d <= config.max_start_offset)) {
    return "first waypoint " + core::short_number(d) + " m from the vehicle (max " +
           core::short_number(config.max_start_offset) + " m)";
  }
  return "";
}

std::vector<Eigen::Vector3d> flight_polyline(const Path& path, const Eigen::Vector3d& vehicle,
                                             double vehicle_yaw, std::vector<double>* yaws) {
  constexpr double kRepeat = 1e-3;  // m
  std::vector<Eigen::Vector3d> pts{vehicle};
  std::vector<double> ys{vehicle_yaw};
  for (std::size_t i = 1; i < path.waypoints.size(); ++i) {
    const double yaw = core::unwrap_near(path.yaws[i], ys.back());
    if ((path.waypoints[i] - pts.back()).norm() < kRepeat) {
      ys.back() = yaw;  // the later heading wins
      continue;
    }
    pts.push_back(path.waypoints[i]);
    ys.push_back(yaw);
  }
  // A one-waypoint path is a goal, not a start: fly to it.
  if (path.waypoints.size() == 1) {
    const double yaw = core::unwrap_near(path.yaws[0], vehicle_yaw);
    if ((path.waypoints[0] - vehicle).norm() < kRepeat) {
      ys.back() = yaw;
    } else {
      pts.push_back(path.waypoints[0]);
      ys.push_back(yaw);
    }
  }
  if (yaws) *yaws = std::move(ys);
  return pts;
}

}  // namespace semx::controller
