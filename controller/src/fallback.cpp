#include "semx/controller/fallback.hpp"

#include <algorithm>
#include <cmath>

namespace semx::controller {
namespace {

// Increments (arc length per knot interval) of a symmetric discrete trapezoid covering `length`:
// none above `cruise`, neighbours differing by at most `ramp`, the first and last at most `ramp`
// (the neighbouring velocity control points are zero at the stops).
std::vector<double> trapezoid_steps(double length, double cruise, double ramp) {
  const auto step = [&](long i, long m) {
    return std::min({static_cast<double>(i + 1) * ramp, static_cast<double>(m - i) * ramp, cruise});
  };
  const auto sum = [&](long m) {
    double s = 0;
    for (long i = 0; i < m; ++i) s += step(i, m);
    return s;
  };
  // Smallest step count whose full-speed trapezoid covers the length; then shrink every step
  // alike, which keeps both limits.
  long m = 1;
  while (sum(m) < length) m *= 2;
  long lo = m / 2 + 1, hi = m;
  if (m == 1) lo = 1;
  while (lo < hi) {
    const long mid = (lo + hi) / 2;
    if (sum(mid) >= length) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  m = hi;
  const double scale = length / sum(m);
  std::vector<double> steps(static_cast<std::size_t>(m));
  for (long i = 0; i < m; ++i) steps[static_cast<std::size_t>(i)] = step(i, m) * scale;
  return steps;
}

// The first control points of a curve starting at `start` with velocity v and braking straight
// along it at the limit (p(0) = Q1, v(0) = (Q2 - Q0)/2dt, a(0) = 0, as the optimised curve
// starts); the last is where it stops. Empty when v is (about) zero.
PositionSpline::Points braking_points(const Eigen::Vector3d& start, const Eigen::Vector3d& v, double ramp,
                                      double dt) {
  PositionSpline::Points q;
  if (!v.allFinite() || v.norm() * dt <= 1e-6) return q;
  const Eigen::Vector3d u = v.normalized();
  q.push_back(start - dt * v);
  q.push_back(start);
  Eigen::Vector3d at = start + dt * v;
  q.push_back(at);
  for (double step = v.norm() * dt - ramp; step > 0; step -= ramp) {
    at += step * u;
    q.push_back(at);
  }
  return q;
}

// Where the fallback returns to the path after braking to `stop`: the first segment's point
// nearest the stop.
Eigen::Vector3d return_point(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& stop) {
  const Eigen::Vector3d start = points.front();
  if (points.size() < 2) return start;
  const Eigen::Vector3d d = points[1] - start;
  return start + d * std::clamp((stop - start).dot(d) / d.squaredNorm(), 0.0, 1.0);
}

constexpr double kSame = 1e-6;  // m

}  // namespace

std::vector<Eigen::Vector3d> fallback_route(const std::vector<Eigen::Vector3d>& points,
                                            const Eigen::Vector3d& start_velocity, double max_acceleration,
                                            double knot_interval) {
  const double dt = knot_interval;
  const PositionSpline::Points brake =
      braking_points(points.front(), start_velocity, max_acceleration * dt * dt, dt);
  std::vector<Eigen::Vector3d> route{points.front()};
  const auto add = [&](const Eigen::Vector3d& p) {
    if ((p - route.back()).norm() > kSame) route.push_back(p);
  };
  if (!brake.empty()) {
    add(brake.back());
    add(return_point(points, brake.back()));
  }
  for (std::size_t i = 1; i < points.size(); ++i) add(points[i]);
  return route;
}

FallbackSpline make_fallback_spline(const std::vector<Eigen::Vector3d>& points,
                                    const Eigen::Vector3d& start_velocity, double max_speed,
                                    double max_acceleration, double knot_interval) {
  const double dt = knot_interval;
  const double cruise = max_speed * dt, ramp = max_acceleration * dt * dt;
  FallbackSpline out;
  out.point_times.push_back(0.0);
  const Eigen::Vector3d start = points.front();
  // The vehicle cannot stop at once: a reference at rest while it moves is flown off by the
  // braking distance (0.2 m at 0.9 m/s), off the path the planner checked. So the curve first
  // brakes along the velocity at the limit, like the vehicle will, then returns to the path.
  PositionSpline::Points q = braking_points(start, start_velocity, ramp, dt);
  const bool moving = !q.empty();
  if (!moving) q.push_back(start);
  for (int k = 0; k < 2; ++k) q.push_back(q.back());
  Eigen::Vector3d at = q.back();
  // Straight on from `from` to `to`, stopping there (three equal control points).
  const auto leg = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    const Eigen::Vector3d d = to - from;
    const double length = d.norm();
    const std::vector<double> steps = trapezoid_steps(length, cruise, ramp);
    double s = 0;
    for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
      s += steps[k];
      q.push_back(from + d * (s / length));
    }
    for (int k = 0; k < 3; ++k) q.push_back(to);
  };
  if (moving) {
    // The braking ray and this leg are the only parts off the path; the clearance check covers both.
    const Eigen::Vector3d back = return_point(points, at);
    if ((back - at).norm() > kSame) leg(at, back);
    at = back;
  }
  for (std::size_t i = 1; i < points.size(); ++i) {
    if ((points[i] - at).norm() > kSame) leg(at, points[i]);
    // The curve reaches a triple's point at the knot of its first copy.
    out.point_times.push_back(static_cast<double>(q.size() - 3) * dt);
    at = points[i];
  }
  while (q.size() < 4) q.push_back(points.back());  // a lone point at rest: hover
  out.spline = PositionSpline(std::move(q), dt);
  return out;
}

}  // namespace semx::controller
