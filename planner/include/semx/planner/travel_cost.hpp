// Travel cost and score of a candidate (paper Eq. 8-9):
//   T_path = max(d / v, w_psi · Δψ / ω)   (CostConfig::turn_while_flying, the default), or
//   T_path = d / v + w_psi · Δψ / ω       (the paper's Eq. 8),
//   Score = (G + R_sem) / T_path,
// d the length of the roadmap path from the vehicle to the node, Δψ the turn from the vehicle's
// heading to the node's best yaw (the smaller way round, in [0, π]). The controller turns while
// it flies, so the first form is the time the flight takes. T_path is floored at
// CostConfig::min_time so that the node under the vehicle cannot score infinitely.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "semx/core/angles.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

inline double travel_time(double distance, double yaw_change, const CostConfig& c) {
  const double fly = distance / c.velocity;
  const double turn = c.yaw_weight * std::abs(yaw_change) / c.yaw_rate;
  const double t = c.turn_while_flying ? std::max(fly, turn) : fly + turn;
  return std::max(t, c.min_time);
}

inline double travel_time(double distance, double from_yaw, double to_yaw, const CostConfig& c) {
  return travel_time(distance, core::yaw_distance(from_yaw, to_yaw), c);
}

// The length of a polyline (m).
inline double path_length(const std::vector<Eigen::Vector3d>& path) {
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

// With `exponent` (CostConfig::time_exponent) T_path^e; 1 is the paper's Eq. 9.
inline double node_score(double gain, double reward, double time, double exponent = 1.0) {
  return (gain + reward) / (exponent == 1.0 ? time : std::pow(time, exponent));
}

}  // namespace semx::planner
