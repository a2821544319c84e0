// Voxel traversal of a segment (Amanatides & Woo 3D DDA), shared by every query that follows a
// line of sight so the mapper's map and its mirrors agree on which voxels a ray crosses.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "semx/map/voxel_key.hpp"

namespace semx::map {

// Calls visit(const VoxelKey&) for every voxel the segment a -> b passes through, in order, from
// a's voxel to b's voxel, both included. Stepping is driven by the exact key difference, so the
// walk always ends in b's voxel and is 6-connected even when floating-point ties occur. Stops
// when visit returns false. Returns false if it stopped early or a point is not representable.
template <class Visit>
bool traverse_segment(const KeyMath& km, const Eigen::Vector3d& a, const Eigen::Vector3d& b, Visit&& visit) {
  VoxelKey ka, kb;
  if (!km.key(a, ka) || !km.key(b, kb)) return false;
  VoxelKey cur = ka;
  if (!visit(static_cast<const VoxelKey&>(cur))) return false;
  if (ka == kb) return true;

  const double inv = km.inv_resolution();
  int step[3];
  int remaining[3];
  double t_max[3];
  double t_delta[3];
  const Eigen::Vector3d d = (b - a) * inv;
  for (int i = 0; i < 3; ++i) {
    const int diff = kb[i] - ka[i];
    remaining[i] = std::abs(diff);
    step[i] = diff > 0 ? 1 : -1;
    if (remaining[i] == 0 || d[i] == 0.0) {
      t_max[i] = std::numeric_limits<double>::infinity();
      t_delta[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    const double start = a[i] * inv;
    const double border = diff > 0 ? ka[i] + 1.0 : static_cast<double>(ka[i]);
    t_max[i] = (border - start) / d[i];
    t_delta[i] = 1.0 / std::abs(d[i]);
  }
  int total = remaining[0] + remaining[1] + remaining[2];
  while (total-- > 0) {
    int axis = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      if (remaining[i] > 0 && (axis < 0 || t_max[i] < best)) {
        axis = i;
        best = t_max[i];
      }
    }
    cur[axis] += step[axis];
    --remaining[axis];
    t_max[axis] += t_delta[axis];
    if (!visit(static_cast<const VoxelKey&>(cur))) return false;
  }
  return true;
}

}  // namespace semx::map
