// Planning time is not free (DESIGN.md §3): each cycle is charged a simulated duration computed
// from the work it did, never from the wall clock, so a run replays identically:
//   charged_s = scale · max(min_s, base_s + per_box_check_s · box checks + per_gain_node_s · gain
//               evaluations + per_ray_step_s · voxels stepped by gain rays
//               + per_search_node_s · nodes settled by the search).
// The defaults are a least-squares fit of the cycle's wall time on the 2-core reference machine
// (semx-perf-planner prints the fit), so charged time ≈ the time this implementation takes there.
// A path planned at message time t is published at t + charged_s at the earliest.
#pragma once

#include <algorithm>

#include "semx/planner/plan_types.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

inline double charged_seconds(const CycleCounters& c, const ChargeConfig& m) {
  const double work = m.base_s + m.per_box_check_s * static_cast<double>(c.box_checks) +
                      m.per_gain_node_s * static_cast<double>(c.gain_evaluations) +
                      m.per_ray_step_s * static_cast<double>(c.ray_steps) +
                      m.per_search_node_s * static_cast<double>(c.search_settled);
  return m.scale * std::max(m.min_s, work);
}

}  // namespace semx::planner
