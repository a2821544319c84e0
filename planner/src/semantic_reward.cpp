#include "semx/planner/semantic_reward.hpp"

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::planner {

double region_reward(const Eigen::Vector3d& p, const SemanticRegion& s, const ViewCone* view) {
  if (!s.active || !(s.radius > 0) || !std::isfinite(s.radius) || !std::isfinite(s.weight) ||
      !(s.weight > 0) || !s.centroid.allFinite() || !p.allFinite()) {
    return 0.0;
  }
  const double d = (p - s.centroid).norm();
  if (d > s.radius) return 0.0;
  if (view) {
    const Eigen::Vector3d to = s.centroid - p;
    if (std::abs(core::wrap_angle(std::atan2(to.y(), to.x()) - view->yaw)) > view->half_fov) return 0.0;
  }
  return s.weight * (1.0 - d / s.radius);
}

double semantic_reward(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions,
                       const std::vector<double>* factors, const ViewCone* view) {
  const bool scaled = factors && factors->size() == regions.size();
  double r = 0.0;
  for (size_t i = 0; i < regions.size(); ++i) {
    const double ri = region_reward(p, regions[i], view);
    if (ri > 0) r += scaled ? ri * (*factors)[i] : ri;
  }
  return r;
}

}  // namespace semx::planner
