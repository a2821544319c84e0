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

bool hold_heading_square_at(std::vector<double>& times, std::vector<double>& yaws, double t, double yaw_at_t,
                            const Eigen::Vector3d& gradient, double hold) {
  const Eigen::Vector2d g2 = gradient.head<2>();
  if (times.size() < 2 || times.size() != yaws.size() || !(g2.norm() > kRidgeGradient)) return false;
  if (!(t > times.front()) || !(t < times.back()) || !(hold > 0.0)) return false;
  const double face = std::atan2(g2.y(), g2.x());
  const double square = yaw_at_t + std::remainder(face - yaw_at_t, M_PI / 2.0);
  // Inside the first and last knots, so that the vehicle's and the goal's headings stay.
  const double a = std::max(t - hold, 0.5 * (times.front() + t));
  const double b = std::min(t + hold, 0.5 * (t + times.back()));
  std::vector<double> nt, ny;
  nt.reserve(times.size() + 2);
  ny.reserve(times.size() + 2);
  for (std::size_t k = 0; k < times.size(); ++k) {
    const bool inner = k > 0 && k + 1 < times.size();
    if (inner && times[k] >= a && times[k] <= b) continue;
    if (times[k] > b && (nt.empty() || nt.back() < a)) {
      nt.insert(nt.end(), {a, b});
      ny.insert(ny.end(), {square, square});
    }
    nt.push_back(times[k]);
    ny.push_back(yaws[k]);
  }
  times = std::move(nt);
  yaws = std::move(ny);
  return true;
}

}  // namespace semx::controller
