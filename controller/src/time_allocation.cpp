#include "semx/controller/time_allocation.hpp"

#include <algorithm>
#include <cmath>

namespace semx::controller {

double TimedPolyline::corner_speed(double angle, double max_speed, double max_acceleration,
                                   double knot_interval) {
  const double s = std::sin(0.5 * std::clamp(angle, 0.0, M_PI));
  if (s < 1e-9) return max_speed;
  return std::min(max_speed, max_acceleration * knot_interval / (2.0 * s));
}

TimedPolyline::TimedPolyline(std::vector<Eigen::Vector3d> points, double start_speed, double max_speed,
                             double max_acceleration, double knot_interval,
                             const std::vector<double>& segment_speed)
    : points_(std::move(points)), a_(max_acceleration) {
  const std::size_t n = points_.size();
  point_times_.assign(n, 0.0);
  if (n < 2) return;
  segments_.resize(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    Segment& s = segments_[i];
    s.start = points_[i];
    const Eigen::Vector3d d = points_[i + 1] - points_[i];
    s.length = d.norm();
    s.dir = s.length > 0 ? Eigen::Vector3d(d / s.length) : Eigen::Vector3d::UnitX();
    length_ += s.length;
  }
  // Speed limit at each point, then forward and backward passes so that every segment can reach
  // its exit speed from its entry speed within the acceleration limit.
  std::vector<double> v(n, max_speed);
  v.front() = std::clamp(start_speed, 0.0, max_speed);
  v.back() = 0.0;
  const bool capped = segment_speed.size() == n - 1;
  auto cap = [&](std::size_t i) {
    return capped ? std::clamp(segment_speed[i], 1e-3, max_speed) : max_speed;
  };
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double c = std::clamp(segments_[i - 1].dir.dot(segments_[i].dir), -1.0, 1.0);
    v[i] = std::min(
        {corner_speed(std::acos(c), max_speed, max_acceleration, knot_interval), cap(i - 1), cap(i)});
  }
  for (std::size_t i = 0; i + 1 < n; ++i) {
    v[i + 1] = std::min(v[i + 1], std::sqrt(v[i] * v[i] + 2 * a_ * segments_[i].length));
  }
  for (std::size_t i = n - 1; i > 0; --i) {
    // The start speed is the vehicle's: it cannot be lowered, so the next point may need to be
    // faster than its own limit asks (the optimiser and time scaling settle the remainder).
    if (i - 1 == 0) break;
    v[i - 1] = std::min(v[i - 1], std::sqrt(v[i] * v[i] + 2 * a_ * segments_[i - 1].length));
  }
  double t = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    Segment& s = segments_[i];
    s.v0 = v[i];
    s.v1 = std::min(v[i + 1], std::sqrt(s.v0 * s.v0 + 2 * a_ * s.length));
    // A start faster than the first segment can shed: decelerate throughout.
    const double reach = std::sqrt(std::max(0.0, s.v0 * s.v0 - 2 * a_ * s.length));
    if (reach > s.v1) s.v1 = reach;
    v[i + 1] = s.v1;
    s.vp = std::min(cap(i), std::sqrt(0.5 * (2 * a_ * s.length + s.v0 * s.v0 + s.v1 * s.v1)));
    s.vp = std::max({s.vp, s.v0, s.v1});
    const double d1 = (s.vp * s.vp - s.v0 * s.v0) / (2 * a_);
    const double d3 = (s.vp * s.vp - s.v1 * s.v1) / (2 * a_);
    const double d2 = std::max(0.0, s.length - d1 - d3);
    s.t1 = (s.vp - s.v0) / a_;
    s.t3 = (s.vp - s.v1) / a_;
    s.t2 = s.vp > 0 ? d2 / s.vp : 0.0;
    s.t_start = t;
    s.time = s.t1 + s.t2 + s.t3;
    t += s.time;
    point_times_[i + 1] = t;
  }
}

double TimedPolyline::distance_in(const Segment& s, double tau) const {
  tau = std::clamp(tau, 0.0, s.time);
  double d;
  if (tau < s.t1) {
    d = s.v0 * tau + 0.5 * a_ * tau * tau;
  } else if (tau < s.t1 + s.t2) {
    d = (s.vp * s.vp - s.v0 * s.v0) / (2 * a_) + s.vp * (tau - s.t1);
  } else {
    const double u = tau - s.t1 - s.t2;
    d = (s.vp * s.vp - s.v0 * s.v0) / (2 * a_) + s.vp * s.t2 + s.vp * u - 0.5 * a_ * u * u;
  }
  return std::clamp(d, 0.0, s.length);
}

const TimedPolyline::Segment* TimedPolyline::segment_at(double t) const {
  if (segments_.empty()) return nullptr;
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                             [](double v, const Segment& s) { return v < s.t_start; });
  return it == segments_.begin() ? &segments_.front() : &*(it - 1);
}

Eigen::Vector3d TimedPolyline::position(double t) const {
  if (segments_.empty()) return points_.empty() ? Eigen::Vector3d::Zero() : points_.front();
  if (t >= duration()) return points_.back();
  const Segment* s = segment_at(t);
  return s->start + s->dir * distance_in(*s, t - s->t_start);
}

double TimedPolyline::speed(double t) const {
  if (segments_.empty() || t >= duration()) return 0.0;
  const Segment* s = segment_at(t);
  const double tau = std::clamp(t - s->t_start, 0.0, s->time);
  if (tau < s->t1) return s->v0 + a_ * tau;
  if (tau < s->t1 + s->t2) return s->vp;
  return std::max(0.0, s->vp - a_ * (tau - s->t1 - s->t2));
}

}  // namespace semx::controller
