#include "semx/controller/grid_distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "semx/map/esdf_distance.hpp"

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
  double u[3];
  for (int a = 0; a < 3; ++a) u[a] = (p[a] - origin_[a]) / resolution_ - 0.5;
  return map::trilinear_distance(
      u, n_, 1.0 / resolution_,
      [this](int x, int y, int z) { return static_cast<double>(values_[index(x, y, z)]); }, gradient);
}

}  // namespace semx::controller
