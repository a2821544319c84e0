#include "semx/core/time_split.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "semx/core/angles.hpp"

namespace semx::core {

const char* to_string(TimeUse u) {
  switch (u) {
    case TimeUse::kNew:
      return "new";
    case TimeUse::kRevisit:
      return "revisit";
    case TimeUse::kTurn:
      return "turn";
    case TimeUse::kHover:
      return "hover";
    case TimeUse::kEndGame:
      return "end_game";
  }
  return "hover";
}

double TimeSplitResult::share(TimeUse u) const {
  return time_f > 0 ? time_s[static_cast<size_t>(u)] / time_f : 0.0;
}

namespace {
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}
}  // namespace

std::string TimeSplitResult::to_json() const {
  std::ostringstream s;
  s << "{\n  \"slice_s\": " << num(options.slice_s) << ",\n  \"move_speed_m_s\": " << num(options.move_speed)
    << ",\n  \"turn_rate_rad_s\": " << num(options.turn_rate) << ",\n  \"new_rate_m3_s\": " << num(options.new_rate)
    << ",\n  \"time_f_s\": " << num(time_f) << ",\n  \"time_settled_s\": " << num(time_settled)
    << ",\n  \"distance_m\": " << num(distance_total_m) << ",\n  \"revisit_by_place_m\": " << num(revisit_by_place_m)
    << ",\n  \"uses\": {";
  for (int i = 0; i < kTimeUses; ++i) {
    const TimeUse u = static_cast<TimeUse>(i);
    s << (i ? "," : "") << "\n    \"" << to_string(u) << "\": {\"time_s\": " << num(time_s[static_cast<size_t>(i)])
      << ", \"share\": " << num(share(u)) << ", \"distance_m\": " << num(distance_m[static_cast<size_t>(i)])
      << ", \"new_m3\": " << num(new_m3[static_cast<size_t>(i)]) << "}";
  }
  s << "\n  },\n  \"slices\": \"";
  for (const TimeSlice& sl : slices) s << kTimeUseLetters[static_cast<size_t>(sl.use)];
  s << "\"\n}\n";
  return s.str();
}

TimeSplit::TimeSplit(TimeSplitOptions options) : options_(options) {
  if (!(options_.slice_s > 0)) options_.slice_s = 0.5;
}

void TimeSplit::on_pose(double t, const Eigen::Vector3d& position, double yaw) {
  if (!std::isfinite(t) || !position.allFinite()) return;
  if (!poses_.empty() && t <= poses_.back().t) return;
  poses_.push_back({t, position, yaw});
}

void TimeSplit::on_covered(double t, int64_t covered) {
  if (!std::isfinite(t)) return;
  if (!covered_.empty() && t < covered_.back().first) return;
  if (!covered_.empty() && covered == covered_.back().second) return;
  covered_.emplace_back(t, covered);
}

TimeSplitResult TimeSplit::finish(double time_f, double time_settled, double voxel_volume) const {
  TimeSplitResult r;
  r.options = options_;
  r.time_f = std::max(0.0, time_f);
  r.time_settled = time_settled;
  const double dt = options_.slice_s;
  const size_t n = static_cast<size_t>(std::ceil(r.time_f / dt - 1e-9));
  // The covered count at t: the last change at or before t.
  size_t ci = 0;
  int64_t covered_now = 0;
  auto covered_at = [&](double t) {
    while (ci < covered_.size() && covered_[ci].first <= t + 1e-9) covered_now = covered_[ci++].second;
    return covered_now;
  };
  size_t pi = 0;
  r.slices.reserve(n);
  int64_t c0 = covered_at(0.0);
  for (size_t k = 0; k < n; ++k) {
    TimeSlice sl;
    sl.t0 = static_cast<double>(k) * dt;
    sl.t1 = std::min(r.time_f, sl.t0 + dt);
    if (pi > 0) sl.points.push_back(poses_[pi - 1].p);
    while (pi < poses_.size() && poses_[pi].t <= sl.t1 + 1e-9) {
      const Pose& q = poses_[pi];
      if (pi > 0) {
        const Pose& p = poses_[pi - 1];
        sl.distance += (q.p - p.p).norm();
        if (std::isfinite(q.yaw) && std::isfinite(p.yaw)) sl.turn += yaw_distance(p.yaw, q.yaw);
      }
      sl.points.push_back(q.p);
      ++pi;
    }
    const int64_t c1 = covered_at(sl.t1);
    sl.new_m3 = static_cast<double>(c1 - c0) * voxel_volume;
    c0 = c1;
    const double len = std::max(1e-9, sl.t1 - sl.t0);
    if (sl.t0 >= time_settled - 1e-9) {
      sl.use = TimeUse::kEndGame;
    } else if (sl.distance / len >= options_.move_speed) {
      sl.use = sl.new_m3 / len >= options_.new_rate ? TimeUse::kNew : TimeUse::kRevisit;
    } else {
      sl.use = sl.turn / len >= options_.turn_rate ? TimeUse::kTurn : TimeUse::kHover;
    }
    const size_t u = static_cast<size_t>(sl.use);
    r.time_s[u] += sl.t1 - sl.t0;
    r.distance_m[u] += sl.distance;
    r.new_m3[u] += sl.new_m3;
    r.distance_total_m += sl.distance;
    r.slices.push_back(std::move(sl));
  }
  // Revisited by place: each slice's flight whose end lies within place_radius of a slice end at
  // least place_age_s earlier.
  for (size_t k = 0; k < r.slices.size(); ++k) {
    const TimeSlice& sl = r.slices[k];
    if (sl.points.empty() || sl.distance <= 0) continue;
    const Eigen::Vector3d& here = sl.points.back();
    for (size_t j = 0; j < k; ++j) {
      const TimeSlice& old = r.slices[j];
      if (old.t1 > sl.t1 - options_.place_age_s) break;
      if (!old.points.empty() && (old.points.back() - here).norm() <= options_.place_radius) {
        r.revisit_by_place_m += sl.distance;
        break;
      }
    }
  }
  return r;
}

}  // namespace semx::core
