// Exact overlap tests between the vehicle's yawed body box and solids. All rotations are about
// z, so each test is a 2D separating-axis (box) or closest-point (cylinder) test plus a z
// interval test.
#pragma once

#include <Eigen/Core>

#include "semx/simulator/solid.hpp"

namespace semx::simulator {

// An upright box: centre, full size, yaw. The vehicle body and the solid boxes are both this.
struct YawBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  double yaw = 0.0;
  Aabb bounds() const;
};

// Positive-volume overlap (touching is not a collision).
bool overlaps(const YawBox& box, const Solid& solid);
bool overlaps(const YawBox& a, const YawBox& b);
// Axis-aligned cube (a voxel) against a solid, positive-volume.
bool overlaps(const Aabb& box, const Solid& solid);

}  // namespace semx::simulator
