#include "semx/fixtures/exploration_sim.hpp"

#include <cstdio>
#include <cstdlib>

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::planner {

ExplorationSim::ExplorationSim(const SyntheticWorld& world, ExplorationPlanner& planner,
                               ExplorationSimOptions options)
    : world_(world), planner_(planner), options_(options), known_(world.resolution()) {
  pose_.position = world.start();
  pose_.yaw = 0.0;
  if (options_.semantic_weight > 0 || options_.region_params) {
    const map::KeyMath km(world.resolution());
    for (size_t i = 0; i < world.objects().size(); ++i) {
      const Box& b = world.objects()[i];
      Object o;
      o.centre = 0.5 * (b.min + b.max);
      o.extent = b.max - b.min;
      o.class_id = world.object_classes()[i];
      o.weight = options_.semantic_weight;
      o.radius = options_.semantic_radius;
      if (options_.region_params && !options_.region_params(o.class_id, b.max - b.min, &o.weight, &o.radius))
        continue;
      const map::VoxelKey lo = km.key(b.min), hi = km.key(b.max);
      for (int32_t z = lo.z; z <= hi.z; ++z)
        for (int32_t y = lo.y; y <= hi.y; ++y)
          for (int32_t x = lo.x; x <= hi.x; ++x) {
            const map::VoxelKey k{x, y, z};
            if (!world.occupied(k)) continue;
            for (const map::VoxelKey& d : map::kFaceNeighbours) {
              if (!world.occupied(k + d)) {
                o.surface.push_back(k);
                break;
              }
            }
          }
      if (!o.surface.empty()) objects_.push_back(std::move(o));
    }
  }
}

void ExplorationSim::update_regions(double t, ExplorationSimResult& r) {
  if (objects_.empty()) return;
  std::vector<SemanticRegion> regions;
  int64_t completed = 0;
  map::StateGrid::Reader reader = known_.reader();
  for (size_t i = 0; i < objects_.size(); ++i) {
    Object& o = objects_[i];
    size_t known = 0;
    for (const map::VoxelKey& k : o.surface) known += reader.state(k) != map::VoxelState::kUnknown;
    const double fraction = static_cast<double>(known) / static_cast<double>(o.surface.size());
    if (fraction >= options_.observed_fraction) o.completed = true;
    completed += o.completed;
    if (known == 0) continue;  // not detected yet
    SemanticRegion s;
    s.id = static_cast<int64_t>(i);
    s.centroid = o.centre;
    s.class_id = o.class_id;
    s.weight = o.weight;
    s.radius = o.radius;
    s.active = !o.completed;
    s.extent = o.extent;
    regions.push_back(s);
  }
  if (completed > r.objects_completed && completed == static_cast<int64_t>(objects_.size()))
    r.objects_time = t;
  r.objects_completed = completed;
  planner_.set_regions(std::move(regions));
}

void ExplorationSim::observe() {
  const auto changes =
      world_.observe(known_, pose_.position, pose_.yaw, options_.camera, options_.pixel_step);
  planner_.on_map_changes(changes);
}

void ExplorationSim::move(double dt) {
  if (holding_ || next_waypoint_ >= path_.waypoints.size()) {
    holding_ = true;
    return;
  }
  double budget = options_.speed * dt;
  double yaw_budget = options_.yaw_rate * dt;
  while (next_waypoint_ < path_.waypoints.size()) {
    const Eigen::Vector3d& w = path_.waypoints[next_waypoint_];
    const double target_yaw = path_.yaws[next_waypoint_];
    const Eigen::Vector3d d = w - pose_.position;
    const double dist = d.norm();
    const double turn = core::wrap_angle(target_yaw - pose_.yaw);
    // Position and yaw move together toward the waypoint; the yaw may finish after the position.
    const double step = std::min(budget, dist);
    if (dist > 1e-9) pose_.position += d * (step / dist);
    distance_ += step;
    budget -= step;
    const double yaw_step = std::clamp(turn, -yaw_budget, yaw_budget);
    pose_.yaw = core::wrap_angle(pose_.yaw + yaw_step);
    yaw_budget -= std::abs(yaw_step);
    if (dist - step < 1e-9 && std::abs(turn - yaw_step) < 1e-6) {
      ++next_waypoint_;
      continue;
    }
    break;
  }
  if (next_waypoint_ >= path_.waypoints.size()) holding_ = true;
}

ExplorationSimResult ExplorationSim::run(
    const std::function<void(double, const ExplorationPlanner::Output&)>& on_step) {
  ExplorationSimResult r;
  planner_.set_map(&known_);
  pose_.utime = 0;
  planner_.set_pose(pose_);
  observe();
  double next_observe = options_.observe_period;
  double next_coverage = options_.coverage_period;
  const int64_t steps = static_cast<int64_t>(std::ceil(options_.max_time / options_.dt));
  const Eigen::Vector3d body = planner_.config().collision.vehicle_size;
  for (int64_t i = 1; i <= steps; ++i) {
    const double t = i * options_.dt;
    move(options_.dt);
    if (world_.collides(pose_.position, body)) ++r.collisions;
    if (t + 1e-9 >= next_observe) {
      observe();
      update_regions(t, r);
      next_observe += options_.observe_period;
    }
    pose_.utime = static_cast<int64_t>(std::llround(t * 1e6));
    planner_.set_pose(pose_);
    if (holding_ && planner_.plan_id() > 0)
      planner_.on_controller_status(ControllerState::kHolding, planner_.plan_id());
    const ExplorationPlanner::Output out = planner_.tick(pose_.utime);
    if (out.status && out.status->iteration > 0 && out.status->counters.total_ms > 0) {
      r.cycle_ms.push_back(out.status->counters.total_ms);
      r.counters.push_back(out.status->counters);
      r.charged_s += out.status->charged_s;
      ++r.cycles;
    }
    if (out.path) {
      path_ = *out.path;
      next_waypoint_ = 0;
      holding_ = false;
      ++r.paths;
      r.released.push_back(*out.path);
    }
    if (options_.coverage_period > 0 && t + 1e-9 >= next_coverage) {
      const double c = world_.coverage(known_);
      r.coverage_curve.emplace_back(t, c);
      if (r.time_85 < 0 && c >= 0.85) r.time_85 = t;
      if (r.time_95 < 0 && c >= 0.95) r.time_95 = t;
      next_coverage += options_.coverage_period;
    }
    if (on_step) on_step(t, out);
    r.time_s = t;
    if (planner_.state() == PlannerState::kDone && !planner_.busy()) {
      r.done = true;
      r.reason = planner_.last_status().reason;
      break;
    }
  }
  r.distance = distance_;
  r.coverage = world_.coverage(known_);
  r.coverage_curve.emplace_back(r.time_s, r.coverage);
  if (r.time_85 < 0 && r.coverage >= 0.85) r.time_85 = r.time_s;
  if (r.time_95 < 0 && r.coverage >= 0.95) r.time_95 = r.time_s;
  // As the evaluator defines them (run_metrics.hpp), on this loop's coverage samples.
  for (const auto& [t, c] : r.coverage_curve) {
    if (r.time_settled < 0 && c >= r.coverage - 0.005) r.time_settled = t;
  }
  if (!r.done) r.reason = planner_.last_status().reason;
  return r;
}

}  // namespace semx::planner
