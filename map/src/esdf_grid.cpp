#include "semx/map/esdf_grid.hpp"

#include <cmath>

#include "semx/map/esdf_distance.hpp"

namespace semx::map {

bool EsdfGrid::voxel_distance(const VoxelKey& k, float* d) const {
  if (empty() || !contains(k)) return false;
  *d = distance[index(k.x - origin.x, k.y - origin.y, k.z - origin.z)];
  return true;
}

bool EsdfGrid::interpolate(const Eigen::Vector3d& p, double* dist, Eigen::Vector3d* gradient) const {
  if (empty() || !p.allFinite()) return false;
  const Eigen::Vector3d lo = origin_point();
  const int n[3] = {nx, ny, nz};
  double u[3];
  for (int a = 0; a < 3; ++a) {
    const double cells = (p[a] - lo[a]) / resolution;
    if (!(cells >= 0.0 && cells < n[a])) return false;
    u[a] = cells - 0.5;
  }
  *dist = trilinear_distance(
      u, n, 1.0 / resolution,
      [&](int x, int y, int z) { return static_cast<double>(distance[index(x, y, z)]); }, gradient);
  return true;
}

}  // namespace semx::map
