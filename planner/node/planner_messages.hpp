// Conversions between the planner's values and its LCM messages (docs/messages.md), and the
// content checks its subscriptions use as `accept` predicates. The planner library knows no
// messages; this file is the only place that knows both.
#pragma once

#include <semx/controller_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>

#include <vector>

#include "semx/planner/plan_types.hpp"
#include "semx/planner/semantic_reward.hpp"

namespace semx::planner {

semx::path_t to_message(const PlannedPath& p, int64_t utime);
semx::roadmap_t to_message(const RoadmapView& v, int64_t utime);
semx::planner_status_t to_message(const StatusReport& s, int64_t utime);

// Position and yaw (about world z) of the body.
VehiclePose to_pose(const semx::odometry_t& m);
std::vector<SemanticRegion> to_regions(const semx::semantic_regions_t& m);

// Finite position within 1e5 m, unit quaternion (±1e-3).
bool accept_odometry(const semx::odometry_t& m);
// num_regions matches the array; centroids, weights and radii finite.
bool accept_regions(const semx::semantic_regions_t& m);
// A known state.
bool accept_controller_status(const semx::controller_status_t& m);

}  // namespace semx::planner
