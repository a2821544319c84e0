// Analytic distance fields and small helpers shared by the controller tests.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "semx/controller/distance_field.hpp"
#include "semx/controller/grid_distance_field.hpp"

namespace semx::controller::test {

// No obstacles anywhere.
class FreeField : public DistanceField {
 public:
  explicit FreeField(double d = 5.0) : d_(d) {}
  double distance(const Eigen::Vector3d&, Eigen::Vector3d* g = nullptr) const override {
    if (g) g->setZero();
    return d_;
  }
  double lipschitz() const override { return 0.0; }

 private:
  double d_;
};

// Free space only within a thin tube around a polyline: distance = top - distance to the
// polyline. Any curve that strays more than (top - bound - pad) from the polyline collides, so
// only the fallback (which stays exactly on it) can pass: an impossible corridor for a smooth
// trajectory.
class TubeField : public DistanceField {
 public:
  TubeField(std::vector<Eigen::Vector3d> polyline, double top) : pts_(std::move(polyline)), top_(top) {}
  double distance(const Eigen::Vector3d& p, Eigen::Vector3d* g = nullptr) const override {
    double best = 1e300;
    Eigen::Vector3d closest = pts_.front();
    for (std::size_t i = 0; i + 1 < pts_.size(); ++i) {
      const Eigen::Vector3d a = pts_[i], d = pts_[i + 1] - pts_[i];
      const double u = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      const Eigen::Vector3d c = a + u * d;
      const double dist = (p - c).norm();
      if (dist < best) {
        best = dist;
        closest = c;
      }
    }
    if (g) *g = best > 1e-12 ? Eigen::Vector3d(-(p - closest) / best) : Eigen::Vector3d::Zero();
    return top_ - best;
  }
  double lipschitz() const override { return 1.0; }

 private:
  std::vector<Eigen::Vector3d> pts_;
  double top_;
};

// One vertical post (a door jamb's end seen from above): distance to the line x = c.x, y = c.y.
class PostField : public DistanceField {
 public:
  explicit PostField(const Eigen::Vector2d& c) : c_(c) {}
  double distance(const Eigen::Vector3d& p, Eigen::Vector3d* g = nullptr) const override {
    const Eigen::Vector2d d = p.head<2>() - c_;
    const double n = d.norm();
    if (g) *g = n > 1e-12 ? Eigen::Vector3d(d.x() / n, d.y() / n, 0.0) : Eigen::Vector3d::Zero();
    return n;
  }
  double lipschitz() const override { return 1.0; }

 private:
  Eigen::Vector2d c_;
};

// A grid sampled from any function at cell centres.
template <class F>
GridDistanceField sample_grid(F f, const Eigen::Vector3d& origin, double res, int nx, int ny, int nz,
                              double max_distance = 3.0, OutsideWindow outside = OutsideWindow::kFree) {
  std::vector<float> v(static_cast<std::size_t>(nx) * ny * nz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        v[static_cast<std::size_t>(x + nx * (y + ny * z))] =
            static_cast<float>(f(origin + (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * res));
  return GridDistanceField(origin, res, nx, ny, nz, std::move(v), max_distance, outside);
}

}  // namespace semx::controller::test
