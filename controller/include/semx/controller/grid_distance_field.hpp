// A DistanceField over a dense grid laid out as ESDF_LOCAL: cell (ix, iy, iz) at index
// ix + nx*(iy + ny*iz), its centre at origin + (i + 0.5)·resolution, values in metres.
//
// Between cell centres the field is map::trilinear_distance (semx/map/esdf_distance.hpp: the one
// ESDF query, which the planner's clearance uses too). Within half a cell of the window's faces
// the border values extend outwards; beyond the window the space is free
// (max_distance, zero gradient) or an obstacle (-max_distance), as configured; a non-finite point
// is an obstacle.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/controller/distance_field.hpp"

namespace semx::controller {

enum class OutsideWindow { kFree, kObstacle };

class GridDistanceField : public DistanceField {
 public:
  GridDistanceField() = default;
  // Throws std::invalid_argument on sizes that do not match, a non-positive resolution or a value
  // that is not finite.
  GridDistanceField(const Eigen::Vector3d& origin, double resolution, int nx, int ny, int nz,
                    std::vector<float> values, double max_distance, OutsideWindow outside);

  // Whether every one of n values is finite, in SIMD (an ESDF_LOCAL holds 3·10^5): the check the
  // constructor makes, for a node to count a message as malformed before it builds a field.
  static bool all_finite(const float* values, std::size_t n);

  double distance(const Eigen::Vector3d& p, Eigen::Vector3d* gradient = nullptr) const override;
  double lipschitz() const override { return lipschitz_; }

  bool empty() const { return values_.empty(); }
  bool contains(const Eigen::Vector3d& p) const;
  const Eigen::Vector3d& origin() const { return origin_; }
  double resolution() const { return resolution_; }
  int nx() const { return n_[0]; }
  int ny() const { return n_[1]; }
  int nz() const { return n_[2]; }
  double max_distance() const { return max_distance_; }
  float value(int ix, int iy, int iz) const { return values_[index(ix, iy, iz)]; }
  std::size_t index(int ix, int iy, int iz) const {
    return static_cast<std::size_t>(ix) +
           static_cast<std::size_t>(n_[0]) *
               (static_cast<std::size_t>(iy) + static_cast<std::size_t>(n_[1]) * iz);
  }

 private:
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double resolution_ = 1.0;
  int n_[3] = {0, 0, 0};
  std::vector<float> values_;
  double max_distance_ = 0.0;
  OutsideWindow outside_ = OutsideWindow::kFree;
  double lipschitz_ = 0.0;
};

}  // namespace semx::controller
