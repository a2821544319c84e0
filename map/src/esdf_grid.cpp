#include "semx/map/esdf_grid.hpp"

#include <algorithm>
#include <cmath>

namespace semx::map {

bool EsdfGrid::voxel_distance(const VoxelKey& k, float* d) const {
  if (empty() || !contains(k)) return false;
  *d = distance[index(k.x - origin.x, k.y - origin.y, k.z - origin.z)];
  return true;
}

bool EsdfGrid::interpolate(const Eigen::Vector3d& p, double* dist, Eigen::Vector3d* gradient) const {
  if (empty() || !p.allFinite()) return false;
  const int n[3] = {nx, ny, nz};
  const int32_t o[3] = {origin.x, origin.y, origin.z};
  int i0[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    // Continuous index in cell-centre units: cell i's centre is at i.
    double q = p[a] / resolution - o[a] - 0.5;
    if (q < -0.5 || q >= n[a] - 0.5) return false;
    q = std::min(std::max(q, 0.0), static_cast<double>(n[a] - 1));
    i0[a] = std::min(static_cast<int>(q), n[a] - 2);
    f[a] = q - i0[a];
  }
  auto at = [&](int dx, int dy, int dz) {
    return static_cast<double>(distance[index(i0[0] + dx, i0[1] + dy, i0[2] + dz)]);
  };
  const double c000 = at(0, 0, 0), c100 = at(1, 0, 0), c010 = at(0, 1, 0), c110 = at(1, 1, 0);
  const double c001 = at(0, 0, 1), c101 = at(1, 0, 1), c011 = at(0, 1, 1), c111 = at(1, 1, 1);
  const double fx = f[0], fy = f[1], fz = f[2];
  const double c00 = c000 + (c100 - c000) * fx, c10 = c010 + (c110 - c010) * fx;
  const double c01 = c001 + (c101 - c001) * fx, c11 = c011 + (c111 - c011) * fx;
  const double c0 = c00 + (c10 - c00) * fy, c1 = c01 + (c11 - c01) * fy;
  *dist = c0 + (c1 - c0) * fz;
  if (gradient) {
    const double gx = ((c100 - c000) * (1 - fy) + (c110 - c010) * fy) * (1 - fz) +
                      ((c101 - c001) * (1 - fy) + (c111 - c011) * fy) * fz;
    const double gy = (c10 - c00) * (1 - fz) + (c11 - c01) * fz;
    const double gz = c1 - c0;
    *gradient = Eigen::Vector3d(gx, gy, gz) / resolution;
  }
  return true;
}

}  // namespace semx::map
