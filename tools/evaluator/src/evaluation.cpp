#include "semx/evaluator/evaluation.hpp"

#include <cmath>
#include <iostream>

namespace semx::evaluator {

namespace {

std::shared_ptr<const simulator::GroundTruth> build_ground_truth(const simulator::World& world, double res) {
  return std::make_shared<const simulator::GroundTruth>(world, res);
}

}  // namespace

Evaluation::Evaluation(simulator::World world, EvaluationOptions options)
    : world_(std::move(world)), options_(std::move(options)), metrics_(options_.metrics) {
  if (!(options_.resolution > 0)) options_.resolution = 0.1;
  gt_ = build_ground_truth(world_, options_.resolution);
  tracker_ = std::make_unique<CoverageTracker>(gt_);
  planner_ = options_.info.planner;
  metrics_.on_coverage(0, 0, tracker_->target_count());
}

bool Evaluation::ensure_resolution(double resolution) {
  if (tracker_->matches(resolution) || !(resolution > 0)) return false;
  std::cerr << "semx-evaluator: the map has " << resolution << " m voxels, not " << tracker_->resolution()
            << " m: rebuilding the ground truth at the map's resolution\n";
  options_.resolution = resolution;
  gt_ = build_ground_truth(world_, resolution);
  tracker_ = std::make_unique<CoverageTracker>(gt_);
  return true;
}

void Evaluation::note_coverage(int64_t utime) {
  metrics_.on_coverage(utime, tracker_->covered(), tracker_->target_count());
  if (!finished()) time_split_.on_covered(static_cast<double>(utime) * 1e-6, tracker_->covered());
  metrics_.on_object_coverage(utime, tracker_->object_covered(), tracker_->object_target_count());
}

void Evaluation::on_map_delta(const map::MapDelta& delta, const map::StateGrid& grid_after) {
  if (finished()) return;
  ++map_deltas_;
  map_seq_ = delta.seq;
  if (ensure_resolution(delta.resolution)) {
    tracker_->reset(grid_after);
  } else {
    tracker_->apply(delta);
  }
  note_coverage(delta.utime);
}

void Evaluation::on_map_reset(const map::StateGrid& grid, int64_t utime, int64_t seq) {
  if (finished()) return;
  ++map_resets_;
  if (seq >= 0) map_seq_ = seq;
  ensure_resolution(grid.resolution());
  tracker_->reset(grid);
  note_coverage(utime);
}

void Evaluation::on_odometry(int64_t utime, const Eigen::Vector3d& position, double yaw) {
  if (!finished()) time_split_.on_pose(static_cast<double>(utime) * 1e-6, position, yaw);
  metrics_.on_odometry(utime, position);
}

void Evaluation::on_collision(int64_t utime, int64_t running_count) {
  metrics_.on_collision(utime, running_count);
}

void Evaluation::on_planner_status(int64_t utime, const std::string& planner, PlannerState state,
                                   const std::string& reason) {
  if (finished()) return;
  if (options_.info.planner.empty() && !planner.empty()) planner_ = planner;
  planner_reason_ = reason;
  metrics_.on_planner_state(utime, state);
}

void Evaluation::on_episode_end(int64_t utime, double wall_s) {
  finish(Termination::kEpisodeEnd, utime, wall_s);
}

void Evaluation::on_node_status(const std::string& node, int pid, int restarts, int64_t utime) {
  if (finished()) return;
  const auto it = nodes_.find(node);
  const bool first = it == nodes_.end();
  const bool again = first ? restarts > 0 : restarts > it->second.restarts ||
                                                (restarts == it->second.restarts && pid != it->second.pid);
  if (again) restarts_.push_back({node, static_cast<double>(utime) * 1e-6, restarts});
  nodes_[node] = {pid, restarts};
}

std::optional<Termination> Evaluation::due(int64_t utime) const {
  if (finished()) return std::nullopt;
  if (const auto done = metrics_.planner_done_utime(); done && utime > *done) {
    return Termination::kPlannerDone;
  }
  if (options_.time_limit_s > 0 && utime >= std::llround(options_.time_limit_s * 1e6)) {
    return Termination::kTimeLimit;
  }
  return std::nullopt;
}

void Evaluation::advance(int64_t utime) { metrics_.advance(utime); }

void Evaluation::finish(Termination why, int64_t utime, double wall_s) {
  if (finished()) return;
  wall_s_ = wall_s;
  // A run stopped or a log ended after the planner's DONE still ended with that DONE.
  if ((why == Termination::kStopped || why == Termination::kLogEnd) && metrics_.planner_done_utime()) {
    why = Termination::kPlannerDone;
  }
  metrics_.finish(why, utime, options_.time_limit_s);
}

void Evaluation::mark_invalid(const std::string& reason) {
  for (const auto& r : invalid_reasons_)
    if (r == reason) return;
  invalid_reasons_.push_back(reason);
}

RunSummary Evaluation::summary() const {
  RunSummary s;
  s.valid = invalid_reasons_.empty();
  for (const auto& r : invalid_reasons_) s.invalid_reason += (s.invalid_reason.empty() ? "" : "; ") + r;
  s.info = options_.info;
  s.info.planner = planner_;
  s.time_f_s = metrics_.time_f_s();
  s.distance_m = metrics_.distance_m();
  s.coverage_pct = metrics_.coverage_pct();
  s.time_r_s = metrics_.time_r_s();
  s.time_95_s = metrics_.time_95_s();
  s.time_settled_s = metrics_.time_settled_s();
  s.end_game_s = metrics_.end_game_s();
  s.object_coverage_pct = metrics_.object_coverage_pct();
  s.time_o_s = metrics_.time_o_s();
  s.collisions = metrics_.collisions();
  s.wall_s = wall_s_;
  s.termination = to_string(metrics_.termination());
  s.planner_state = to_string(metrics_.planner_state());
  s.planner_reason = planner_reason_;
  s.sim_s = static_cast<double>(metrics_.now_utime()) * 1e-6;
  s.realtime_factor = wall_s_ > 0 ? s.sim_s / wall_s_ : 0.0;
  if (options_.time_limit_s > 0) s.time_limit_s = options_.time_limit_s;
  s.coverage_threshold_pct = 100.0 * options_.metrics.coverage_threshold;
  s.object_threshold_pct = 100.0 * options_.metrics.object_threshold;
  s.resolution_m = tracker_->resolution();
  s.target_voxels = tracker_->target_count();
  s.covered_voxels = tracker_->covered();
  s.object_voxels = tracker_->object_target_count();
  s.map_seq = map_seq_;
  s.restarts = restarts_;
  s.coverage = metrics_.samples();
  s.trajectory = metrics_.trajectory();
  const double res = tracker_->resolution();
  // A run whose coverage never settled (no map) has no end game.
  s.time_split = time_split_.finish(s.time_f_s, s.time_settled_s.value_or(s.time_f_s), res * res * res);
  return s;
}

void Evaluation::save(core::ByteWriter& w, Saved& saved) const {
  metrics_.save(w, saved);
  w.str(planner_);
  w.str(planner_reason_);
  w.i64(map_deltas_);
  w.i64(map_resets_);
  w.i64(map_seq_);
  w.u32(static_cast<uint32_t>(nodes_.size()));
  for (const auto& [name, n] : nodes_) {
    w.str(name);
    w.i32(n.pid);
    w.i32(n.restarts);
  }
  w.u32(static_cast<uint32_t>(restarts_.size()));
  for (const auto& r : restarts_) {
    w.str(r.node);
    w.f64(r.t_s);
    w.i32(r.restarts);
  }
}

void Evaluation::restore(core::ByteReader& r) {
  metrics_.restore(r);
  planner_ = r.str();
  planner_reason_ = r.str();
  map_deltas_ = r.i64();
  map_resets_ = r.i64();
  map_seq_ = r.i64();
  nodes_.clear();
  for (uint32_t i = 0, n = r.u32(); i < n; ++i) {
    std::string name = r.str();
    NodeSeen seen;
    seen.pid = r.i32();
    seen.restarts = r.i32();
    nodes_[std::move(name)] = seen;
  }
  restarts_.clear();
  for (uint32_t i = 0, n = r.u32(); i < n; ++i) {
    NodeRestart x;
    x.node = r.str();
    x.t_s = r.f64();
    x.restarts = r.i32();
    restarts_.push_back(std::move(x));
  }
}

}  // namespace semx::evaluator
