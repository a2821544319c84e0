#include "semx/evaluator/run_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

namespace {

void put_opt(core::ByteWriter& w, const std::optional<int64_t>& v) {
  w.u8(v ? 1 : 0);
  w.i64(v.value_or(0));
}

std::optional<int64_t> get_opt(core::ByteReader& r) {
  const bool has = r.u8() != 0;
  const int64_t v = r.i64();
  return has ? std::optional<int64_t>(v) : std::nullopt;
}

void put_vec(core::ByteWriter& w, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) w.f64(v[i]);
}

Eigen::Vector3d get_vec(core::ByteReader& r) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = r.f64();
  return v;
}

// The series from the element before `saved` (it may have been replaced since) to the end.
template <class T, class Put>
void put_tail(core::ByteWriter& w, const std::vector<T>& v, size_t& saved, Put put) {
  const size_t from = std::min(saved, v.size()) > 0 ? std::min(saved, v.size()) - 1 : 0;
  w.u64(from);
  w.u64(v.size() - from);
  for (size_t i = from; i < v.size(); ++i) put(v[i]);
  saved = v.size();
}

template <class T, class Get>
void get_tail(core::ByteReader& r, std::vector<T>& v, Get get) {
  const uint64_t from = r.u64();
  const uint64_t n = r.u64();
  if (from > v.size()) throw std::runtime_error("evaluator state: a record is missing before this one");
  if (n > r.remaining()) throw std::out_of_range("unexpected end of data");
  v.resize(from);
  for (uint64_t i = 0; i < n; ++i) v.push_back(get());
}

}  // namespace

void RunMetrics::save(core::ByteWriter& w, Saved& saved) const {
  w.i64(now_utime_);
  w.u8(have_odometry_ ? 1 : 0);
  w.i64(last_odometry_utime_);
  put_vec(w, last_position_);
  w.f64(distance_m_);
  w.i64(covered_);
  w.i64(target_);
  put_opt(w, time_r_utime_);
  put_opt(w, time_95_utime_);
  w.i64(object_covered_);
  w.i64(object_target_);
  put_opt(w, time_o_utime_);
  w.i64(collision_events_);
  w.i64(collision_count_);
  w.i32(static_cast<int32_t>(planner_state_));
  put_opt(w, done_utime_);
  w.i64(next_sample_utime_);
  put_tail(w, trajectory_, saved.trajectory, [&](const Eigen::Vector3d& p) { put_vec(w, p); });
  put_tail(w, samples_, saved.samples, [&](const CoverageSample& s) {
    w.f64(s.t_s);
    w.f64(s.coverage_pct);
    w.f64(s.distance_m);
    w.i64(s.covered);
    w.f64(s.object_coverage_pct);
  });
  put_tail(w, growth_, saved.growth, [&](const std::pair<int64_t, int64_t>& g) {
    w.i64(g.first);
    w.i64(g.second);
  });
}

void RunMetrics::restore(core::ByteReader& r) {
  now_utime_ = r.i64();
  have_odometry_ = r.u8() != 0;
  last_odometry_utime_ = r.i64();
  last_position_ = get_vec(r);
  distance_m_ = r.f64();
  covered_ = r.i64();
  target_ = r.i64();
  time_r_utime_ = get_opt(r);
  time_95_utime_ = get_opt(r);
  object_covered_ = r.i64();
  object_target_ = r.i64();
  time_o_utime_ = get_opt(r);
  collision_events_ = r.i64();
  collision_count_ = r.i64();
  planner_state_ = planner_state_from_int(r.i32());
  done_utime_ = get_opt(r);
  next_sample_utime_ = r.i64();
  get_tail(r, trajectory_, [&] { return get_vec(r); });
  get_tail(r, samples_, [&] {
    CoverageSample s;
    s.t_s = r.f64();
    s.coverage_pct = r.f64();
    s.distance_m = r.f64();
    s.covered = r.i64();
    s.object_coverage_pct = r.f64();
    return s;
  });
  get_tail(r, growth_, [&] {
    const int64_t u = r.i64();
    return std::pair<int64_t, int64_t>(u, r.i64());
  });
}

}  // namespace semx::evaluator
