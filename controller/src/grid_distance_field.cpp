#include "semx/controller/grid_distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "semx/map/esdf_distance.hpp"

namespace semx::controller {

namespace {

// max |v[i + step] - v[i]| over i < n (0 when n is 0): Eigen's packet reduction (SSE), whose
// result does not depend on the order, the values being finite (the constructor checks).
float max_abs_step(const float* v, std::size_t n, std::size_t step) {
  if (n == 0) return 0.0f;
  using Run = Eigen::Map<const Eigen::ArrayXf>;
  const Eigen::Index len = static_cast<Eigen::Index>(n);
  return (Run(v + step, len) - Run(v, len)).abs().maxCoeff();
}

}  // namespace

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
  if (!all_finite(values_.data(), values_.size())) throw std::invalid_argument("a value is not finite");
  // The interpolant's slope along an axis is a blend of neighbour differences along it, so the
  // largest difference per axis bounds each gradient component. Every ESDF_LOCAL builds a field
  // (3·10^5 cells at the defaults): the differences are taken as flat runs of the array, in SIMD,
  // instead of a branch per cell per axis (that loop was 4 % of a process set's CPU, perf).
  const std::size_t row = static_cast<std::size_t>(nx), plane = row * static_cast<std::size_t>(ny);
  const float* v = values_.data();
  float dmax[3] = {0, 0, 0};
  for (std::size_t r = 0; r < values_.size(); r += row)
    dmax[0] = std::max(dmax[0], max_abs_step(v + r, row - 1, 1));
  for (std::size_t p = 0; p < values_.size(); p += plane)
    dmax[1] = std::max(dmax[1], max_abs_step(v + p, plane - row, row));
  dmax[2] = max_abs_step(v, values_.size() - plane, plane);
  lipschitz_ = Eigen::Vector3d(dmax[0], dmax[1], dmax[2]).norm() / resolution_;
}

bool GridDistanceField::all_finite(const float* values, std::size_t n) {
  // x - x is 0 for a finite x and NaN otherwise, so the sum is 0 exactly when every value is
  // finite: a packet reduction, not a branch per value.
  const Eigen::Map<const Eigen::ArrayXf> v(values, static_cast<Eigen::Index>(n));
  return (v - v).sum() == 0.0f;
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
