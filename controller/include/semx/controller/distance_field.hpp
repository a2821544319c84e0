// What the controller asks of an ESDF: the signed distance to the nearest obstacle (m, positive
// outside) and its gradient at any point. Implemented by the dense grid of ESDF_LOCAL and, in
// tests, by analytic fields.
#pragma once

#include <Eigen/Core>

namespace semx::controller {

class DistanceField {
 public:
  virtual ~DistanceField() = default;
  // Distance at p; when `gradient` is non-null it receives ∂distance/∂p.
  virtual double distance(const Eigen::Vector3d& p, Eigen::Vector3d* gradient = nullptr) const = 0;
  // An upper bound of |∇distance| anywhere: how much the field may drop between two dense
  // samples, which the clearance check pads its bound with.
  virtual double lipschitz() const = 0;
};

}  // namespace semx::controller
