#include "semx/planner/semantic_fuel_strategy.hpp"

#include <algorithm>
#include <cmath>

#include "semx/core/angles.hpp"
#include "semx/planner/travel_cost.hpp"

#include "semx/runtime/semantic_classes.hpp"

namespace semx::planner {

SemanticFuelStrategy::SemanticFuelStrategy(const PlannerConfig& config)
    : FuelStrategy(config),
      rules_(config.semantic_fuel),
      yaw_rate_(config.cost.yaw_rate),
      cost_(config.cost),
      gains_(config.gain) {
  if (rules_.dep_first_s > 0 || rules_.greedy_ratio > 0 || rules_.tour_doors > 0)
    dep_ = std::make_unique<DepStrategy>(config, false);
}

std::vector<int> door_rooms(const std::vector<std::vector<Eigen::Vector3d>>& paths,
                            const std::vector<SemanticRegion>& regions, double radius, double height) {
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  std::vector<int> doors;
  for (size_t r = 0; r < regions.size(); ++r) {
    // A door stays a room's boundary once its leaf is fully observed (active only says it was seen).
    if (regions[r].class_id == door && regions[r].centroid.allFinite()) doors.push_back(static_cast<int>(r));
  }
  std::vector<int> room(paths.size(), -1);
  const double r2 = radius * radius;
  for (size_t i = 0; i < paths.size(); ++i) {
    for (const Eigen::Vector3d& p : paths[i]) {
      for (int d : doors) {
        const Eigen::Vector3d& c = regions[static_cast<size_t>(d)].centroid;
        if ((p - c).head<2>().squaredNorm() <= r2 && std::abs(p.z() - c.z()) <= height) room[i] = d;
      }
    }
  }
  return room;
}

bool near_unfinished_object(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions,
                            double margin) {
  for (const SemanticRegion& r : regions) {
    const auto cls = runtime::class_from_id(r.class_id);
    if (!cls || *cls == runtime::SemanticClass::kDoor || runtime::class_info(*cls).structural) continue;
    if (!r.active || !r.centroid.allFinite() || !r.extent.allFinite() || !(r.extent.minCoeff() > 0)) continue;
    const Eigen::Vector3d half = 0.5 * r.extent + Eigen::Vector3d::Constant(margin);
    if (((p - r.centroid).cwiseAbs().array() <= half.array()).all()) return true;
  }
  return false;
}

double share_near_unfinished_objects(const std::vector<map::VoxelKey>& voxels, const map::KeyMath& keys,
                                     const std::vector<SemanticRegion>& regions, double margin,
                                     size_t samples) {
  if (voxels.empty() || samples == 0) return 0.0;
  const size_t stride = std::max<size_t>(1, (voxels.size() + samples - 1) / samples);
  size_t tested = 0, near = 0;
  for (size_t i = 0; i < voxels.size(); i += stride) {
    ++tested;
    if (near_unfinished_object(keys.center(voxels[i]), regions, margin)) ++near;
  }
  return static_cast<double>(near) / static_cast<double>(tested);
}

int count_doors(const std::vector<SemanticRegion>& regions, double radius) {
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  std::vector<Eigen::Vector2d> seen;
  for (const SemanticRegion& r : regions) {
    if (r.class_id != door || !r.centroid.allFinite()) continue;
    const Eigen::Vector2d c = r.centroid.head<2>();
    const bool again = std::any_of(seen.begin(), seen.end(), [&](const Eigen::Vector2d& s) {
      return (s - c).squaredNorm() <= radius * radius;
    });
    if (!again) seen.push_back(c);
  }
  return static_cast<int>(seen.size());
}

bool near_door(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions, double radius) {
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  for (const SemanticRegion& r : regions) {
    if (r.class_id == door && r.centroid.allFinite() &&
        (p - r.centroid).head<2>().squaredNorm() <= radius * radius)
      return true;
  }
  return false;
}

std::vector<SemanticRegion> open_doors(const map::StateGrid& grid, const std::vector<SemanticRegion>& regions,
                                       double radius, double min_share) {
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  std::vector<SemanticRegion> out;
  const double step = grid.resolution();
  const int n = static_cast<int>(std::floor(radius / step));
  map::StateGrid::Reader r = grid.reader();
  for (const SemanticRegion& d : regions) {
    if (d.class_id != door || !d.centroid.allFinite()) continue;
    if (min_share > 0) {
      int64_t all = 0, unknown = 0;
      for (int i = -n; i <= n; ++i) {
        for (int j = -n; j <= n; ++j) {
          if (i * i + j * j > n * n) continue;
          ++all;
          const Eigen::Vector3d p = d.centroid + Eigen::Vector3d(i * step, j * step, 0.0);
          if (r.state(grid.keys().key(p)) == map::VoxelState::kUnknown) ++unknown;
        }
      }
      if (static_cast<double>(unknown) < min_share * static_cast<double>(all)) continue;
    }
    out.push_back(d);
  }
  return out;
}

void add_room_change_cost(const std::vector<int>& room, double cost, TourProblem& problem) {
  const size_t n = static_cast<size_t>(problem.n);
  auto of = [&](size_t node) { return node == 0 ? -1 : room[node - 1]; };
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 1; j < n; ++j) {
      if (i != j && of(i) != of(j)) problem.cost[i * n + j] += cost;
    }
  }
}

void add_doorway_first_cost(const std::vector<bool>& doorway, double cost, TourProblem& problem) {
  if (std::none_of(doorway.begin(), doorway.end(), [](bool d) { return d; })) return;
  for (size_t j = 0; j < doorway.size(); ++j) {
    if (!doorway[j]) problem.cost[j + 1] += cost;
  }
}

void SemanticFuelStrategy::add_tour_costs(const PlanContext& ctx, const GridSearch& tree,
                                          const std::vector<Eigen::Vector3d>& reps,
                                          const std::vector<Eigen::Vector3d>& means,
                                          TourProblem& problem) const {
  if (!ctx.regions || ctx.regions->empty()) return;
  if (rules_.doorway_first_cost > 0) {
    std::vector<bool> doorway(means.size(), false);
    for (size_t i = 0; i < means.size(); ++i)
      doorway[i] = near_door(means[i], *ctx.regions, rules_.doorway_radius);
    add_doorway_first_cost(doorway, rules_.doorway_first_cost, problem);
  }
  if (!(rules_.door_cost > 0)) return;
  std::vector<std::vector<Eigen::Vector3d>> paths;
  paths.reserve(reps.size());
  for (const Eigen::Vector3d& p : reps) paths.push_back(tree.tree_path(p));
  add_room_change_cost(door_rooms(paths, *ctx.regions, rules_.door_radius, rules_.door_height),
                       rules_.door_cost, problem);
}

}  // namespace semx::planner

namespace semx::planner {

double SemanticFuelStrategy::latency_weight(const PlanContext& ctx, const FrontierClusters::Cluster& cluster,
                                            double coverage) const {
  if (!ctx.regions || ctx.regions->empty()) return coverage;
  double factor = 1.0;
  // 64 voxels spread over the cluster give its share to a few per cent, at a cost per plan that
  // does not grow with the cluster.
  if (rules_.object_weight != 0)
    factor += rules_.object_weight * share_near_unfinished_objects(cluster.voxels, ctx.grid->keys(),
                                                                   *ctx.regions, rules_.object_margin, 64);
  if (rules_.door_weight > 0 && near_door(cluster.mean, doors_, rules_.doorway_radius))
    factor += rules_.door_weight;
  return coverage * factor;
}

bool SemanticFuelStrategy::promoted(const PlanContext& ctx, const FrontierClusters::Cluster& cluster) const {
  if (!ctx.regions) return false;
  if (rules_.door_clusters && near_door(cluster.mean, *ctx.regions, rules_.doorway_radius)) return true;
  if (!rules_.object_pockets) return false;
  if (rules_.object_reach > 0 && (cluster.mean - ctx.pose.position).norm() > rules_.object_reach)
    return false;
  return near_unfinished_object(cluster.mean, *ctx.regions, rules_.object_margin);
}

}  // namespace semx::planner

namespace semx::planner {

void SemanticFuelStrategy::reset() {
  FuelStrategy::reset();
  if (dep_) dep_->reset();
  turns_done_ = 0;
  turn_ = Goal();
  first_utime_ = -1;
  dep_now_ = false;
  doors_handed_over_ = false;
}

void SemanticFuelStrategy::on_map_changes(const std::vector<map::VoxelChange>& changes) {
  FuelStrategy::on_map_changes(changes);
  if (dep_) dep_->on_map_changes(changes);
}

void SemanticFuelStrategy::on_map_reset() {
  FuelStrategy::on_map_reset();
  if (dep_) dep_->on_map_reset();
}

void SemanticFuelStrategy::on_gain_invalidated(const std::vector<map::VoxelKey>& keys) {
  FuelStrategy::on_gain_invalidated(keys);
  if (dep_) dep_->on_gain_invalidated(keys);
}

std::optional<double> SemanticFuelStrategy::goal_score(PlanContext& ctx, const Goal& goal) {
  if (dep_now_) return dep_->goal_score(ctx, goal);
  return FuelStrategy::goal_score(ctx, goal);
}

void SemanticFuelStrategy::reject_goal(const Goal& goal, int64_t until_cycle) {
  FuelStrategy::reject_goal(goal, until_cycle);
  if (dep_) dep_->reject_goal(goal, until_cycle);
}

RoadmapView SemanticFuelStrategy::roadmap(const Goal* goal) const {
  return dep_now_ ? dep_->roadmap(goal) : FuelStrategy::roadmap(goal);
}

PlanOutcome SemanticFuelStrategy::plan(PlanContext& ctx) {
  if (first_utime_ < 0) first_utime_ = ctx.pose.utime;
  if (rules_.dep_first_s > 0 || rules_.tour_doors > 0) {
    const bool was = dep_now_;
    dep_now_ = dep_phase(ctx);
    if (dep_now_) return dep_->plan(ctx);
    // The hand-over: FUEL plans a tour now, whatever DEP's goal was.
    if (was) ctx.need_goal = true;
  }
  if (turns_done_ < rules_.start_turns) {
    if (turn_.valid && !ctx.need_goal) {
      PlanOutcome o;
      o.goal = turn_;
      return o;
    }
    if (turn_.valid) ++turns_done_;
    if (turns_done_ < rules_.start_turns) {
      turn_ = turn_in_place(ctx.pose.position, ctx.pose.yaw, 2.0 * core::kPi / rules_.start_turns, yaw_rate_);
      PlanOutcome o;
      o.goal = turn_;
      return o;
    }
  }
  doors_.clear();
  if (rules_.door_weight > 0 && ctx.regions)
    doors_ = open_doors(*ctx.grid, *ctx.regions, rules_.door_probe_radius, rules_.door_open_share);
  if (rules_.greedy_ratio > 0) return plan_greedy(ctx);
  return FuelStrategy::plan(ctx);
}

bool SemanticFuelStrategy::dep_phase(const PlanContext& ctx) {
  if (rules_.dep_first_s > 0 &&
      1e-6 * static_cast<double>(ctx.pose.utime - first_utime_) < rules_.dep_first_s)
    return true;
  if (rules_.tour_doors <= 0 || doors_handed_over_) return false;
  // Once: a door that drops out of the regions (merged, or a detection withdrawn) does not send
  // the vehicle back to DEP's order halfway through the tour.
  doors_handed_over_ = ctx.regions && count_doors(*ctx.regions, rules_.door_radius) >= rules_.tour_doors;
  return !doors_handed_over_;
}

double SemanticFuelStrategy::dep_rate(PlanContext& ctx, const Goal& goal) {
  gains_.set_ignored(ctx.unobservable);
  GainStats stats;
  const NodeGain g = gains_.evaluate(*ctx.grid, goal.position, &stats);
  ctx.counters->gain_evaluations += stats.evaluations;
  ctx.counters->rays += stats.rays;
  ctx.counters->ray_steps += stats.steps;
  const double gain = gains_.goal_gain(g, ctx.pose.yaw, goal.yaw);
  double length = 0.0;
  Eigen::Vector3d from = ctx.pose.position;
  for (const Eigen::Vector3d& w : goal.waypoints) {
    length += (w - from).norm();
    from = w;
  }
  return node_score(gain, 0.0, travel_time(length, ctx.pose.yaw, goal.yaw, cost_));
}

PlanOutcome SemanticFuelStrategy::plan_greedy(PlanContext& ctx) {
  const bool need = ctx.need_goal;
  const Goal* flown = ctx.flown;
  if (dep_now_ && !need && flown) {
    // DEP's goal is flown as DEP flies it (its switches by the main loop's hysteresis) until it is
    // no longer informative; then the next goal is chosen as at a goal reached.
    if (dep_->goal_score(ctx, *flown)) return dep_->plan(ctx);
    ctx.need_goal = true;
    ctx.flown = nullptr;
  }
  PlanOutcome out = FuelStrategy::plan(ctx);
  const bool choosing = ctx.need_goal || switched();
  if (choosing && out.goal.valid) {
    PlanContext d = ctx;
    d.need_goal = true;
    d.flown = nullptr;
    PlanOutcome dep = dep_->plan(d);
    dep_now_ = dep.goal.valid && dep.goal.score > rules_.greedy_ratio * dep_rate(ctx, out.goal);
    if (dep_now_) out = std::move(dep);
  } else if (choosing) {
    dep_now_ = false;
  }
  ctx.need_goal = need;
  ctx.flown = flown;
  return out;
}

}  // namespace semx::planner
