#include "semx/controller/body_heading.hpp"

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

}  // namespace semx::controller
