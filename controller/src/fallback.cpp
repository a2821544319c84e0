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

}  // namespace

FallbackSpline make_fallback_spline(const std::vector<Eigen::Vector3d>& points, double max_speed,
                                    double max_acceleration, double knot_interval) {
  const double dt = knot_interval;
  const double cruise = max_speed * dt, ramp = max_acceleration * dt * dt;
  FallbackSpline out;
  PositionSpline::Points q;
  out.point_times.push_back(0.0);
  for (int k = 0; k < 3; ++k) q.push_back(points.front());
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector3d a = points[i - 1], d = points[i] - points[i - 1];
    const double length = d.norm();
    const std::vector<double> steps = trapezoid_steps(length, cruise, ramp);
    double s = 0;
    for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
      s += steps[k];
      q.push_back(a + d * (s / length));
    }
    // The curve reaches a triple's point at the knot of its first copy.
    out.point_times.push_back(static_cast<double>(q.size()) * dt);
    for (int k = 0; k < 3; ++k) q.push_back(points[i]);
  }
  while (q.size() < 4) q.push_back(points.back());  // a lone point: hover
  out.spline = PositionSpline(std::move(q), dt);
  return out;
}

}  // namespace semx::controller
