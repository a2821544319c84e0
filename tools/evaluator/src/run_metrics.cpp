#include "semx/evaluator/run_metrics.hpp"

#include <cmath>

namespace semx::evaluator {

const char* to_string(Termination t) {
  switch (t) {
    case Termination::kRunning:
      return "running";
    case Termination::kPlannerDone:
      return "planner_done";
    case Termination::kTimeLimit:
      return "time_limit";
    case Termination::kEpisodeEnd:
      return "episode_end";
    case Termination::kStopped:
      return "stopped";
    case Termination::kLogEnd:
      return "log_end";
  }
  return "running";
}

namespace {
double seconds(int64_t utime) { return static_cast<double>(utime) * 1e-6; }

double percent(int64_t covered, int64_t target) {
  return target > 0 ? 100.0 * static_cast<double>(covered) / static_cast<double>(target) : 0.0;
}

// The first update at or above `threshold` (a fraction) fixes `at`; later ones do not move it.
void note_threshold(int64_t utime, int64_t covered, int64_t target, double threshold,
                    std::optional<int64_t>& at) {
  if (!at && target > 0 && static_cast<double>(covered) / static_cast<double>(target) >= threshold)
    at = utime;
}
}  // namespace

RunMetrics::RunMetrics(MetricsOptions options) : options_(options) {}

void RunMetrics::note_time(int64_t utime) { now_utime_ = std::max(now_utime_, utime); }

void RunMetrics::on_odometry(int64_t utime, const Eigen::Vector3d& position) {
  if (finished() || !position.allFinite()) return;
  if (have_odometry_ && utime <= last_odometry_utime_) return;
  if (have_odometry_) distance_m_ += (position - last_position_).norm();
  have_odometry_ = true;
  last_odometry_utime_ = utime;
  last_position_ = position;
  if (trajectory_.empty() || (position - trajectory_.back()).norm() >= options_.trajectory_step_m) {
    trajectory_.push_back(position);
  }
  note_time(utime);
}

void RunMetrics::on_object_coverage(int64_t utime, int64_t covered, int64_t target) {
  if (finished()) return;
  object_covered_ = covered;
  object_target_ = target;
  note_threshold(utime, covered, target, options_.object_threshold, time_o_utime_);
  note_time(utime);
}

double RunMetrics::object_coverage_pct() const { return percent(object_covered_, object_target_); }

std::optional<double> RunMetrics::time_o_s() const {
  if (!time_o_utime_) return std::nullopt;
  return seconds(*time_o_utime_);
}

void RunMetrics::on_coverage(int64_t utime, int64_t covered, int64_t target) {
  if (finished()) return;
  covered_ = covered;
  target_ = target;
  note_threshold(utime, covered, target, options_.coverage_threshold, time_r_utime_);
  note_threshold(utime, covered, target, options_.high_threshold, time_95_utime_);
  if (growth_.empty() || covered > growth_.back().second) growth_.emplace_back(utime, covered);
  note_time(utime);
}

void RunMetrics::on_collision(int64_t utime, int64_t running_count) {
  if (finished()) return;
  ++collision_events_;
  collision_count_ = std::max(collision_count_, running_count);
  note_time(utime);
}

void RunMetrics::on_planner_state(int64_t utime, PlannerState state) {
  if (finished()) return;
  planner_state_ = state;
  if (state == PlannerState::kDone && !done_utime_) done_utime_ = utime;
  note_time(utime);
}

void RunMetrics::advance(int64_t utime) {
  if (finished()) return;
  note_time(utime);
  if (utime < next_sample_utime_) return;
  sample(utime);
  const int64_t period = std::max<int64_t>(1, std::llround(options_.sample_period_s * 1e6));
  next_sample_utime_ = (utime / period + 1) * period;
}

void RunMetrics::sample(int64_t utime) {
  CoverageSample s;
  s.t_s = seconds(utime);
  s.coverage_pct = coverage_pct();
  s.distance_m = distance_m_;
  s.covered = covered_;
  s.object_coverage_pct = object_coverage_pct();
  if (!samples_.empty() && samples_.back().t_s >= s.t_s) {
    s.t_s = samples_.back().t_s;
    samples_.back() = s;
  } else {
    samples_.push_back(s);
  }
}

void RunMetrics::finish(Termination why, int64_t utime, double time_limit_s) {
  if (finished() || why == Termination::kRunning) return;
  note_time(utime);
  int64_t end = now_utime_;
  switch (why) {
    case Termination::kPlannerDone:
      end = done_utime_ ? *done_utime_ : utime;
      break;
    case Termination::kTimeLimit:
      end = time_limit_s > 0 ? std::llround(time_limit_s * 1e6) : utime;
      break;
    case Termination::kEpisodeEnd:
      end = utime;
      break;
    default:
      break;
  }
  end_utime_ = end;
  time_f_s_ = seconds(end);
  sample(end);
  termination_ = why;
}

double RunMetrics::time_f_s() const { return finished() ? time_f_s_ : seconds(now_utime_); }

double RunMetrics::coverage_pct() const { return percent(covered_, target_); }

std::optional<double> RunMetrics::time_r_s() const {
  if (!time_r_utime_) return std::nullopt;
  return seconds(*time_r_utime_);
}

std::optional<double> RunMetrics::time_95_s() const {
  if (!time_95_utime_) return std::nullopt;
  return seconds(*time_95_utime_);
}

std::optional<double> RunMetrics::time_settled_s() const {
  if (growth_.empty() || target_ <= 0) return std::nullopt;
  // The first update whose coverage is within settled_points of the final one (the last entry
  // holds the final covered count).
  const double final_pct = coverage_pct();
  for (const auto& [utime, covered] : growth_) {
    if (percent(covered, target_) >= final_pct - options_.settled_points) return seconds(utime);
  }
  return seconds(growth_.back().first);
}

std::optional<double> RunMetrics::end_game_s() const {
  const std::optional<double> settled = time_settled_s();
  if (!settled) return std::nullopt;
  return std::max(0.0, time_f_s() - *settled);
}

std::optional<double> RunMetrics::planner_done_s() const {
  if (!done_utime_) return std::nullopt;
  return seconds(*done_utime_);
}

std::optional<Eigen::Vector3d> RunMetrics::position() const {
  if (!have_odometry_) return std::nullopt;
  return last_position_;
}

}  // namespace semx::evaluator
