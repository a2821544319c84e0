#include "semx/controller/yaw_profile.hpp"

#include <algorithm>
#include <cmath>

namespace semx::controller {
namespace {

// Piecewise-linear heading target through (times[k], yaws[k]), constant outside.
double target_at(const std::vector<double>& times, const std::vector<double>& yaws, double t) {
  if (t <= times.front()) return yaws.front();
  if (t >= times.back()) return yaws.back();
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - times.begin());
  const double span = times[k] - times[k - 1];
  const double w = span > 0 ? (t - times[k - 1]) / span : 1.0;
  return yaws[k - 1] + w * (yaws[k] - yaws[k - 1]);
}

double step_toward(double from, double to, double max_step) {
  const double d = to - from;
  if (std::abs(d) <= max_step) return to;
  return from + std::copysign(max_step, d);
}

}  // namespace

void add_yaw_profile(Trajectory& trajectory, const std::vector<double>& times,
                     const std::vector<double>& yaws, double max_yaw_rate) {
  auto& q = trajectory.position.control_points();
  const double dt = trajectory.position.knot_interval();
  const double max_step = max_yaw_rate * dt;
  const std::size_t n = q.size();
  std::vector<double> y(n, yaws.front());
  // Control point i sits near the curve at time (i-1)·dt; y[0] mirrors y[2] about y[1] so the
  // spline starts exactly at the vehicle's heading.
  y[1] = yaws.front();
  for (std::size_t i = 2; i < n; ++i)
    y[i] = step_toward(y[i - 1], target_at(times, yaws, (i - 1.0) * dt), max_step);
  y[0] = 2.0 * y[1] - y[2];
  const double last = yaws.back();
  const auto settled = [&] {
    const std::size_t m = y.size();
    return y[m - 1] == last && y[m - 2] == last && y[m - 3] == last;
  };
  while (!settled()) {
    y.push_back(step_toward(y.back(), last, max_step));
    q.push_back(q.back());
  }
  YawSpline::Points yc(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) yc[i](0) = y[i];
  trajectory.yaw = YawSpline(std::move(yc), dt);
  trajectory.position = PositionSpline(q, dt);
}

}  // namespace semx::controller
