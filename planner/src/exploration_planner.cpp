#include "semx/planner/exploration_planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "semx/core/angles.hpp"
#include "semx/core/stopwatch.hpp"
#include "semx/planner/charge_model.hpp"

namespace semx::planner {

ExplorationPlanner::ExplorationPlanner(const PlannerConfig& config)
    : config_(config),
      kind_(config.kind()),
      strategy_(make_strategy(config)),
      checker_(config.collision),
      frontiers_(config.sampling.cluster_size),
      gains_(config.gain),
      rng_(static_cast<uint64_t>(config.seed)) {}

void ExplorationPlanner::reset() {
  strategy_->reset();
  rng_.reseed(static_cast<uint64_t>(config_.seed));
  pose_.reset();
  state_ = PlannerState::kInit;
  reason_.clear();
  iteration_ = 0;
  next_cycle_utime_ = -1;
  no_goal_cycles_ = 0;
  goal_ = Goal();
  controller_trigger_ = controller_rejected_ = controller_holding_ = false;
  init_reported_ = false;
  pending_ = Pending();
  last_status_ = StatusReport();
  unobservable_.clear();
  arrived_utime_ = short_since_ = released_utime_ = -1;
  yields_.clear();
  open_known_ = -1;
  if (grid_) frontiers_.reset(*grid_);
  strategy_->on_map_reset();
}

void ExplorationPlanner::set_map(const map::StateGrid* grid) {
  if (grid == grid_) return;
  grid_ = grid;
  checker_.set_grid(grid);
  if (grid_) on_map_reset();
}

void ExplorationPlanner::on_map_changes(const std::vector<map::VoxelChange>& changes) {
  if (!grid_) return;
  frontiers_.update(*grid_, changes);
  // The path check's ESDF cache keeps what the changes leave true (without, it was refilled
  // whole after every update).
  checker_.note_changes(changes);
  strategy_->on_map_changes(changes);
}

void ExplorationPlanner::on_map_reset() {
  if (!grid_) return;
  frontiers_.reset(*grid_);
  strategy_->on_map_reset();
}

void ExplorationPlanner::set_pose(const VehiclePose& pose) {
  if (!pose.position.allFinite() || !std::isfinite(pose.yaw)) return;
  pose_ = pose;
}

void ExplorationPlanner::on_controller_status(ControllerState state, int64_t plan_id, int64_t utime) {
  if (!goal_.valid) return;
  const int64_t lost_after = std::llround(config_.loop.lost_path_s * 1e6);
  if (plan_id <= 0 && (state == ControllerState::kIdle || state == ControllerState::kStaleInput) &&
      utime >= 0 && released_utime_ >= 0 && utime - released_utime_ >= lost_after && !controller_trigger_) {
    // A controller that has taken a path never reports plan 0 again in an episode: this one was
    // restarted, and our path is not flown any more.
    controller_trigger_ = true;
    controller_rejected_ = false;
    controller_reason_ = "the controller has no path (restarted): planning again";
    return;
  }
  if (plan_id != plan_id_) {
    // A plan id this planner never sent (ids count up from 1): the controller took someone else's
    // path, so ours is not flown any more. Once it rejected or stopped on that path, the vehicle
    // hovers: plan again from where it is (a foreign NaN path or one into a wall froze a run for
    // its whole time limit). Our own earlier plans are history and are ignored.
    const bool foreign = plan_id <= 0 || plan_id > plan_id_;
    if (foreign && !controller_trigger_ &&
        (state == ControllerState::kRejected || state == ControllerState::kBraking)) {
      controller_trigger_ = true;
      controller_rejected_ = false;  // nothing wrong with our goal
      controller_reason_ = "controller stopped on a path this planner did not send";
    }
    return;
  }
  controller_holding_ = state == ControllerState::kHolding;
  if (state == ControllerState::kBraking || state == ControllerState::kStaleInput ||
      state == ControllerState::kRejected) {
    if (!controller_trigger_) {
      controller_trigger_ = true;
      controller_rejected_ = state == ControllerState::kRejected;
      controller_reason_ = state == ControllerState::kBraking      ? "controller braked"
                           : state == ControllerState::kStaleInput ? "controller inputs stale"
                                                                   : "controller rejected the path";
    }
  }
}

void ExplorationPlanner::track_arrival(int64_t utime) {
  const bool within =
      goal_.valid && pose_ && (pose_->position - goal_.position).norm() <= config_.loop.goal_tolerance &&
      (controller_holding_ || core::yaw_distance(pose_->yaw, goal_.yaw) <= config_.loop.yaw_tolerance);
  if (!within) {
    arrived_utime_ = -1;
  } else if (arrived_utime_ < 0) {
    arrived_utime_ = utime;
  }
}

int64_t ExplorationPlanner::reached_utime(int64_t utime) const {
  return (arrived_utime_ >= 0 ? arrived_utime_ : utime) +
         static_cast<int64_t>(std::llround(config_.loop.dwell_s * 1e6));
}

bool ExplorationPlanner::goal_reached(int64_t utime) {
  track_arrival(utime);
  return arrived_utime_ >= 0 && utime >= reached_utime(utime);
}

bool ExplorationPlanner::held_short(int64_t utime) {
  if (!controller_holding_ || !goal_.valid || !pose_ ||
      (pose_->position - goal_.position).norm() <= config_.loop.goal_tolerance) {
    short_since_ = -1;
    return false;
  }
  if (short_since_ < 0) short_since_ = utime;
  return utime - short_since_ >= static_cast<int64_t>(std::llround(config_.loop.short_hold_s * 1e6));
}

void ExplorationPlanner::add_unobservable(const std::vector<map::VoxelKey>& keys) {
  for (const map::VoxelKey& k : keys) unobservable_.insert(k);
  if (strategy_ && !keys.empty()) strategy_->on_gain_invalidated(keys);
}

void ExplorationPlanner::mark_unobservable(CycleCounters& c) {
  if (!grid_ || !pose_) return;
  core::Stopwatch w;
  std::vector<map::VoxelKey> keys;
  GainStats stats;
  gains_.set_ignored(&unobservable_);
  gains_.evaluate(*grid_, pose_->position, pose_->yaw, &keys, &stats);
  for (const map::VoxelKey& k : keys) unobservable_.insert(k);
  if (!keys.empty()) strategy_->on_gain_invalidated(keys);
  c.gain_evaluations += stats.evaluations;
  c.rays += stats.rays;
  c.ray_steps += stats.steps;
  c.gain_ms += w.ms();
}

void ExplorationPlanner::open_yield(double gain) {
  if (config_.loop.yield_goals <= 0 || !grid_) return;
  open_promise_ = gain;
  open_known_ = grid_->known_voxels();
}

void ExplorationPlanner::close_yield() {
  if (open_known_ < 0 || !grid_) return;
  yields_.push_back({open_promise_, grid_->known_voxels() - open_known_});
  while (yields_.size() > static_cast<size_t>(config_.loop.yield_goals)) yields_.pop_front();
  open_known_ = -1;
}

double ExplorationPlanner::min_gain_now() const {
  const double base = config_.gain.min_gain;
  if (config_.loop.yield_goals <= 0 || yields_.size() < static_cast<size_t>(config_.loop.yield_goals))
    return base;
  double promised = 0, delivered = 0;
  for (const Yield& y : yields_) promised += y.promised, delivered += static_cast<double>(y.delivered);
  // Delivery is counted in voxels and the gain in weighted voxels (a surface voxel counts 4):
  // while goals deliver at least what they promised the threshold is DEP's own.
  const double ratio = promised > 0 ? std::clamp(delivered / promised, 1e-3, 1.0) : 1.0;
  return base / ratio;
}

bool ExplorationPlanner::path_blocked() const {
  if (!goal_.valid || !pose_ || goal_.waypoints.size() < 2) return false;
  // The oracle's legs cross space the live map does not know yet, which every check below calls
  // blocked; it planned them on the true map, which does not change.
  if (strategy_->trusts_own_paths()) return false;
  const std::vector<Eigen::Vector3d>& w = goal_.waypoints;
  // The segment the vehicle is on: the nearest one to it.
  size_t seg = 0;
  double best = 1e300;
  Eigen::Vector3d on = w[0];
  for (size_t i = 0; i + 1 < w.size(); ++i) {
    const Eigen::Vector3d d = w[i + 1] - w[i];
    const double t =
        d.squaredNorm() > 0 ? std::clamp((pose_->position - w[i]).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    const Eigen::Vector3d q = w[i] + t * d;
    const double dist = (q - pose_->position).squaredNorm();
    if (dist < best) {
      best = dist;
      seg = i;
      on = q;
    }
  }
  if (!checker_.root_edge_free(on, w[seg + 1])) return true;
  for (size_t i = seg + 1; i + 1 < w.size(); ++i) {
    if (!checker_.edge_free(w[i], w[i + 1])) return true;
  }
  return false;
}

StatusReport ExplorationPlanner::make_status(PlannerState state, const std::string& reason,
                                             const CycleCounters& c, double charged, const Goal& best,
                                             const RoadmapView* view) const {
  StatusReport s;
  s.planner = to_string(kind_);
  s.state = state;
  s.reason = reason;
  s.iteration = iteration_;
  if (view) {
    s.num_nodes = static_cast<int32_t>(view->nodes.size());
    s.num_edges = static_cast<int32_t>(view->edges.size());
  }
  if (best.valid) {
    s.goal = best.position;
    s.best_gain = best.gain;
    s.best_reward = best.reward;
    s.best_score = best.score;
  } else if (goal_.valid) {
    // The cycle kept the goal flown (DEP's ranking found nothing above the switch bar): its values.
    s.goal = goal_.position;
    s.best_gain = goal_.gain;
    s.best_reward = goal_.reward;
    s.best_score = goal_.score;
  }
  s.counters = c;
  s.charged_s = charged;
  return s;
}

ExplorationPlanner::Output ExplorationPlanner::tick(int64_t utime) {
  bool due = false;
  Output out = poll(utime, due);
  if (!due) return out;
  run_cycle(utime);
  if (pending_.active && utime >= pending_.ready_utime) release(out, utime);
  return out;
}

void ExplorationPlanner::run_due_cycle(int64_t utime) { run_cycle(utime); }

int64_t ExplorationPlanner::min_charge_us() const {
  return static_cast<int64_t>(std::llround(config_.charge.scale * config_.charge.min_s * 1e6));
}

ExplorationPlanner::Output ExplorationPlanner::poll(int64_t utime, bool& cycle_due) {
  Output out;
  cycle_due = false;
  // Arrival is watched on every tick, and a goal reached starts a cycle at once, not at the next
  // 1/rate_hz slot: at 4 Hz a vehicle waited 0.74 s at each goal instead of the dwell's 0.3 s.
  track_arrival(utime);
  if (pending_.active) {
    if (utime >= pending_.ready_utime) release(out, utime);
    return out;
  }
  if (state_ == PlannerState::kDone) return out;
  if (!grid_ || !pose_) {
    if (!init_reported_) {
      init_reported_ = true;
      last_status_ = make_status(PlannerState::kInit, !grid_ ? "waiting for the map" : "waiting for odometry",
                                 CycleCounters(), 0.0, Goal(), nullptr);
      out.status = last_status_;
    }
    return out;
  }
  cycle_due = next_cycle_utime_ < 0 || utime >= next_cycle_utime_ ||
              (arrived_utime_ >= 0 && utime >= reached_utime(utime));
  return out;
}

int64_t ExplorationPlanner::quiet_until(int64_t utime) const {
  if (pending_.active) return pending_.ready_utime;
  if (state_ == PlannerState::kDone) return std::numeric_limits<int64_t>::max();
  if (!grid_ || !pose_ || next_cycle_utime_ < 0) return utime;
  // A goal may be reached before the next slot (arrival counts from the next tick at the earliest).
  return goal_.valid ? std::min(next_cycle_utime_, reached_utime(utime)) : next_cycle_utime_;
}

void ExplorationPlanner::run_cycle(int64_t utime) {
  core::CpuStopwatch total;
  CycleCounters c;
  ++iteration_;
  checker_.reset_counters();
  PlanContext ctx;
  ctx.grid = grid_;
  ctx.pose = *pose_;
  ctx.regions = &regions_;
  ctx.frontiers = &frontiers_;
  ctx.unobservable = &unobservable_;
  ctx.cycle = iteration_;
  ctx.recovering = no_goal_cycles_ > 0;
  ctx.min_gain = min_gain_now();
  ctx.rng = &rng_;
  ctx.counters = &c;

  bool need = !goal_.valid;
  std::string why = goal_.valid ? "" : "no goal";
  if (goal_.valid) {
    if (controller_trigger_) {
      need = true;
      why = controller_reason_;
      if (controller_rejected_) strategy_->reject_goal(goal_, iteration_ + config_.loop.blacklist_cycles);
    } else if (goal_reached(utime)) {
      need = true;
      why = "goal reached";
      mark_unobservable(c);
      strategy_->reject_goal(goal_, iteration_ + config_.loop.visited_cycles);
    } else if (path_blocked()) {
      need = true;
      why = "path blocked";
    } else if (held_short(utime)) {
      need = true;
      why = "controller holds short of the goal";
      strategy_->reject_goal(goal_, iteration_ + config_.loop.blacklist_cycles);
    }
  }
  controller_trigger_ = controller_rejected_ = false;
  ctx.need_goal = need;
  if (!need) {
    ctx.flown = &goal_;
    ctx.switch_factor = goal_.held ? std::numeric_limits<double>::infinity() : config_.loop.hysteresis;
  }

  const bool run = need || !strategy_->receding_horizon();
  PlanOutcome o;
  if (run) o = strategy_->plan(ctx);
  if (run && !need) {
    const std::optional<double> current = strategy_->goal_score(ctx, goal_);
    if (!current) {
      need = true;
      why = "goal no longer informative";
    } else if (o.tour_stops == 0 && !goal_.held && o.goal.valid && o.goal.node != goal_.node &&
               o.goal.score > config_.loop.hysteresis * *current) {
      need = true;
      std::ostringstream s;
      s << "better goal (node " << o.goal.node << " score " << o.goal.score << " vs node " << goal_.node
        << " " << *current << ")";
      why = s.str();
      // The goal left behind waits blacklist_cycles before it can be chosen again: two goals
      // whose scores each beat the other by the hysteresis once the vehicle turns toward it
      // held an in-process env3 exploration switching every 1.5 s for 500 s.
      strategy_->reject_goal(goal_, iteration_ + config_.loop.blacklist_cycles);
    }
  }

  Pending p;
  p.active = true;
  PlannerState next = state_;
  std::string reason;
  if (need && o.goal.valid) {
    p.has_path = true;
    p.goal = o.goal;
    no_goal_cycles_ = 0;
    next = PlannerState::kExecuting;
    std::ostringstream s;
    s << why << ": goal (" << o.goal.position.x() << ", " << o.goal.position.y() << ", "
      << o.goal.position.z() << ") gain " << o.goal.gain << " reward " << o.goal.reward << " score "
      << o.goal.score;
    if (o.tour_stops > 0) s << " (end game: first of a tour of " << o.tour_stops << " stops)";
    if (o.pocket_stops > 0) s << " (first of " << o.pocket_stops << " pockets before a far goal)";
    if (o.goal.look) s << " (a look across a cut of the roadmap)";
    reason = s.str();
  } else if (need) {
    if (why == "path blocked") {
      // Nothing else to fly and the path ahead is blocked: hold where the vehicle is.
      p.has_path = true;
      p.goal.valid = false;
      p.goal.position = pose_->position;
      p.goal.yaw = pose_->yaw;
      p.goal.waypoints = {pose_->position};
      p.goal.yaws = {pose_->yaw};
    }
    goal_ = Goal();  // nothing to fly
    close_yield();
    ++no_goal_cycles_;
    const int limit = o.unreachable_informative > 0
                          ? std::max(config_.loop.done_cycles, config_.loop.max_recovery_cycles)
                          : config_.loop.done_cycles;
    next = (no_goal_cycles_ >= limit && iteration_ > o.skipped_until) || o.finished
               ? PlannerState::kDone
               : PlannerState::kRecovering;
    reason = next == PlannerState::kDone ? o.reason : why + ": " + o.reason;
  } else {
    next = PlannerState::kExecuting;
    reason = "flying to the goal";
  }

  c.box_checks += checker_.box_checks();
  c.total_ms = total.ms();
  c.cpu_ms = total.cpu_ms();
  const double charged = charged_seconds(c, config_.charge);
  p.ready_utime = utime + static_cast<int64_t>(std::llround(charged * 1e6));
  if (run || next != state_) {
    p.roadmap = strategy_->roadmap(p.has_path ? &p.goal : (goal_.valid ? &goal_ : nullptr));
    p.roadmap->iteration = iteration_;
    p.status = make_status(next, reason, c, charged, o.goal, &*p.roadmap);
  }
  state_ = next == PlannerState::kExecuting && p.has_path ? PlannerState::kPlanning : next;
  reason_ = reason;
  pending_ = std::move(p);
  const int64_t period = static_cast<int64_t>(std::llround(1e6 / config_.rate_hz));
  next_cycle_utime_ = std::max(pending_.ready_utime, utime + period);
}

void ExplorationPlanner::release(Output& out, int64_t utime) {
  Pending p = std::move(pending_);
  pending_ = Pending();
  if (p.has_path) {
    if (pose_ && (pose_->position - p.goal.waypoints.front()).norm() > config_.loop.max_start_offset) {
      // The vehicle moved on while this was planned: plan again from where it is now.
      goal_ = Goal();
      next_cycle_utime_ = utime;
      state_ = PlannerState::kPlanning;
      if (p.status) {
        p.status->state = state_;
        p.status->reason = "dropped a path the vehicle has left; replanning";
      }
    } else {
      goal_ = p.goal;  // invalid for a hold: the next cycle plans again
      close_yield();
      if (goal_.valid) open_yield(goal_.gain);
      controller_holding_ = false;
      arrived_utime_ = short_since_ = -1;
      released_utime_ = utime;
      PlannedPath path;
      path.plan_id = ++plan_id_;
      path.waypoints = p.goal.waypoints;
      path.yaws = p.goal.yaws;
      out.path = std::move(path);
      if (goal_.valid) state_ = PlannerState::kExecuting;
      if (p.status) p.status->state = state_;
    }
  }
  if (p.status) {
    last_status_ = *p.status;
    out.status = std::move(p.status);
  }
  if (p.roadmap) out.roadmap = std::move(p.roadmap);
}

}  // namespace semx::planner
