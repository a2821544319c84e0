// The semantic reward of a roadmap node (paper Eq. 6-7):
//   R_i(n) = w_i (1 - d_i / r_i) for d_i = |p_n - p_i| ≤ r_i, else 0;   R_sem(n) = Σ_i R_i(n).
// Regions whose object is fully observed stop attracting: the semantics module clears `active`
// (semantic_region_t.active, from its observed fraction) and such a region rewards nothing. The
// paper leaves this open; without it the vehicle would keep returning to objects it has seen.
// Regions with a non-positive or non-finite radius, weight or centroid are ignored.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace semx::planner {

struct SemanticRegion {
  int64_t id = 0;
  int class_id = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // p_i, m
  double weight = 0.0;                                 // w_i
  double radius = 0.0;                                 // r_i, m
  bool active = true;                                  // false once fully observed
  // The object's bounding box size (semantic_region_t.extent), m; zero when unknown. The paper's
  // reward does not use it (semantic-fuel does).
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
};

// The camera's horizontal view from a node: regions outside it reward nothing when one is given
// (RewardConfig::in_view, an ablation; the paper's reward counts every region within r_i).
struct ViewCone {
  double yaw = 0.0;       // rad
  double half_fov = 0.0;  // rad
};

// R_i(n) of one region.
double region_reward(const Eigen::Vector3d& p, const SemanticRegion& region, const ViewCone* view = nullptr);
// R_sem(n); `factors`, when given and one per region, multiply each region's R_i.
double semantic_reward(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions,
                       const std::vector<double>* factors = nullptr, const ViewCone* view = nullptr);

}  // namespace semx::planner
