#include "semx/controller/body_heading.hpp"

#include <algorithm>
#include <cmath>

#include "semx/controller/clearance.hpp"

namespace semx::controller {

int square_headings_near_obstacles(const std::vector<Eigen::Vector3d>& polyline, std::vector<double>& yaws,
                                   const DistanceField& field, double within) {
  if (!(within > 0.0)) return 0;
  constexpr double kQuarter = M_PI / 2.0;
  int turned = 0;
  for (std::size_t k = 1; k < polyline.size() && k < yaws.size(); ++k) {
    Eigen::Vector3d g;
    const double d = field.distance(polyline[k], &g);
    const Eigen::Vector2d g2 = g.head<2>();
    if (!(d < within) || !(g2.norm() > kRidgeGradient)) continue;
    // A face looks along the obstacle's direction at every quarter turn from it.
    const double face = std::atan2(g2.y(), g2.x());
    const double turn = std::remainder(face - yaws[k], kQuarter);  // in [-45°, 45°]
    if (std::abs(turn) < 1e-9) continue;
    yaws[k] += turn;
    ++turned;
  }
  return turned;
}

HeadingRamp heading_for_limits(double yaw, const std::vector<ReachLimit>& limits, double max_rate,
                               double half_xy, double half_z) {
  HeadingRamp best{limits.empty() ? 0.0 : limits.front().time, yaw, 0.0};
  if (limits.empty()) return best;
  double first = limits.front().time, last = first;
  for (const ReachLimit& l : limits) {
    first = std::min(first, l.time);
    last = std::max(last, l.time);
  }
  best.time = first;
  const auto room = [&](const HeadingRamp& r) {
    double least = 1e300;
    for (const ReachLimit& l : limits)
      least = std::min(least, l.allowed - footprint_reach(l.direction, r.at(l.time), half_xy, half_z));
    return least;
  };
  // The room is the smallest of a few piecewise-sinusoidal functions of the heading: each limit's
  // own square (its best) and a grid of 0.5° between, then 0.05° around the best, find its maximum
  // within a millimetre.
  std::vector<double> headings;
  constexpr double kQuarter = M_PI / 2.0, kStep = M_PI / 360.0;
  for (const ReachLimit& l : limits) {
    const Eigen::Vector2d d = l.direction.head<2>();
    if (d.norm() > 0.0) headings.push_back(yaw + std::remainder(std::atan2(d.y(), d.x()) - yaw, kQuarter));
  }
  for (double turn = -kQuarter / 2; turn <= kQuarter / 2 + 1e-12; turn += kStep)
    headings.push_back(yaw + turn);
  // Rates only where the limits span time; 0 first, so a steady heading wins a tie.
  std::vector<double> rates = {0.0};
  if (last - first > 1e-6 && max_rate > 0.0) {
    constexpr int kRates = 5;
    for (int k = 1; k <= kRates; ++k)
      rates.insert(rates.end(), {max_rate * k / kRates, -max_rate * k / kRates});
  }
  double best_room = room(best);
  const auto consider = [&](const HeadingRamp& c) {
    const double r = room(c);
    const bool steadier = std::abs(c.rate) < std::abs(best.rate) - 1e-12;
    const bool as_steady = std::abs(c.rate) < std::abs(best.rate) + 1e-12;
    if (r > best_room + 1e-12 ||
        (r > best_room - 1e-12 &&
         (steadier || (as_steady && std::abs(c.yaw - yaw) < std::abs(best.yaw - yaw))))) {
      best = c;
      best_room = r;
    }
  };
  for (const double rate : rates)
    for (const double h : headings) consider(HeadingRamp{first, h, rate});
  const HeadingRamp coarse = best;
  for (int k = -10; k <= 10; ++k) consider(HeadingRamp{first, coarse.yaw + k * kStep / 10, coarse.rate});
  return best;
}

bool hold_heading(std::vector<double>& times, std::vector<double>& yaws, double inner_a, double inner_b,
                  double hold, const HeadingRamp& ramp) {
  if (times.size() < 2 || times.size() != yaws.size() || !(inner_a <= inner_b)) return false;
  if (!(inner_a > times.front()) || !(inner_b < times.back()) || !(hold > 0.0)) return false;
  const double a = std::max(inner_a - hold, 0.5 * (times.front() + inner_a));
  const double b = std::min(inner_b + hold, 0.5 * (inner_b + times.back()));
  std::vector<double> nt, ny;
  nt.reserve(times.size() + 2);
  ny.reserve(times.size() + 2);
  for (std::size_t k = 0; k < times.size(); ++k) {
    const bool inner = k > 0 && k + 1 < times.size();
    if (inner && times[k] >= a && times[k] <= b) continue;
    if (times[k] > b && (nt.empty() || nt.back() < a)) {
      nt.insert(nt.end(), {a, b});
      ny.insert(ny.end(), {ramp.at(a), ramp.at(b)});
    }
    nt.push_back(times[k]);
    ny.push_back(yaws[k]);
  }
  times = std::move(nt);
  yaws = std::move(ny);
  return true;
}

}  // namespace semx::controller
