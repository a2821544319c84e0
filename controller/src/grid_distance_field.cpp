#include "semx/controller/grid_distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semx::controller {

GridDistanceField::GridDistanceField(const Eigen::Vector3d& origin, double resolution, int nx, int ny, int nz,
                                     std::vector<float> values, double max_distance, OutsideWindow outside)
    : origin_(origin),
      resolution_(resolution),
      n_{nx, ny, nz},
      values_(std::move(values)),
      max_distance_(max_distance),
      outside_(outside) {
  if (!(resolution > 0) || !std::isfinite(resolution))
    throw std::invalid_argument("resolution must be positive");
  if (nx <= 0 || ny <= 0 || nz <= 0) throw std::invalid_argument("grid sizes must be positive");
  if (!origin.allFinite()) throw std::invalid_argument("origin must be finite");
  if (values_.size() !=
      static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz)) {
    throw std::invalid_argument("value count is not nx*ny*nz");
  }
  // The interpolant's slope along an axis is a blend of neighbour differences along it, so the
  // largest difference per axis bounds each gradient component.
  float dmax[3] = {0, 0, 0};
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      const std::size_t row = index(0, y, z);
      for (int x = 0; x < nx; ++x) {
        const float v = values_[row + x];
        if (x + 1 < nx) dmax[0] = std::max(dmax[0], std::abs(values_[row + x + 1] - v));
        if (y + 1 < ny) dmax[1] = std::max(dmax[1], std::abs(values_[row + x + nx] - v));
        if (z + 1 < nz)
          dmax[2] = std::max(dmax[2], std::abs(values_[row + x + static_cast<std::size_t>(nx) * ny] - v));
      }
    }
  }
  lipschitz_ = Eigen::Vector3d(dmax[0], dmax[1], dmax[2]).norm() / resolution_;
}

bool GridDistanceField::contains(const Eigen::Vector3d& p) const {
  for (int a = 0; a < 3; ++a) {
    const double u = (p[a] - origin_[a]) / resolution_;
    if (!(u >= 0.0 && u <= n_[a])) return false;
  }
  return true;
}

double GridDistanceField::distance(const Eigen::Vector3d& p, Eigen::Vector3d* gradient) const {
  if (gradient) gradient->setZero();
  // A point that is nowhere is never safe.
  if (!p.allFinite()) return -max_distance_;
  if (values_.empty() || !contains(p)) {
    return outside_ == OutsideWindow::kFree ? max_distance_ : -max_distance_;
  }
  // Neighbouring centres i0, i1 and weight w of i1 per axis; past the outermost centres both
  // are the border cell (the value extends, the slope is zero).
  int i0[3], i1[3];
  double w[3], slope[3];
  for (int a = 0; a < 3; ++a) {
    const double u = (p[a] - origin_[a]) / resolution_ - 0.5;
    const int lo = static_cast<int>(std::floor(u));
    if (lo < 0) {
      i0[a] = i1[a] = 0;
      w[a] = 0.0;
      slope[a] = 0.0;
    } else if (lo >= n_[a] - 1) {
      i0[a] = i1[a] = n_[a] - 1;
      w[a] = 0.0;
      slope[a] = 0.0;
    } else {
      i0[a] = lo;
      i1[a] = lo + 1;
      w[a] = u - lo;
      slope[a] = 1.0 / resolution_;
    }
  }
  const double c000 = values_[index(i0[0], i0[1], i0[2])], c100 = values_[index(i1[0], i0[1], i0[2])];
  const double c010 = values_[index(i0[0], i1[1], i0[2])], c110 = values_[index(i1[0], i1[1], i0[2])];
  const double c001 = values_[index(i0[0], i0[1], i1[2])], c101 = values_[index(i1[0], i0[1], i1[2])];
  const double c011 = values_[index(i0[0], i1[1], i1[2])], c111 = values_[index(i1[0], i1[1], i1[2])];
  const double wx = w[0], wy = w[1], wz = w[2];
  const double c00 = c000 + wx * (c100 - c000), c10 = c010 + wx * (c110 - c010);
  const double c01 = c001 + wx * (c101 - c001), c11 = c011 + wx * (c111 - c011);
  const double c0 = c00 + wy * (c10 - c00), c1 = c01 + wy * (c11 - c01);
  if (gradient) {
    const double dx0 = (1 - wy) * (c100 - c000) + wy * (c110 - c010);
    const double dx1 = (1 - wy) * (c101 - c001) + wy * (c111 - c011);
    (*gradient)[0] = ((1 - wz) * dx0 + wz * dx1) * slope[0];
    (*gradient)[1] = ((1 - wz) * (c10 - c00) + wz * (c11 - c01)) * slope[1];
    (*gradient)[2] = (c1 - c0) * slope[2];
  }
  return c0 + wz * (c1 - c0);
}

}  // namespace semx::controller
