// Uniform cubic B-spline in Dim dimensions (the position and yaw of a trajectory).
//
// N control points Q_0..Q_{N-1} and a knot interval dt describe a curve on [0, (N-3)·dt]; on
// [j·dt, (j+1)·dt] it depends on Q_j..Q_{j+3} only. Why this model: a derivative of a B-spline is
// a B-spline of the control points' differences, and a B-spline lies in the convex hull of its
// control points, so bounding the norms of (Q_{i+1}-Q_i)/dt and (Q_{i+2}-2Q_{i+1}+Q_i)/dt² bounds
// velocity and acceleration at every instant, not just at samples.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace semx::controller {

// Cubic uniform B-spline basis at local parameter s ∈ [0, 1] of one segment, for derivative
// order 0..3 with respect to s (divide by dt^order for time derivatives).
inline void cubic_basis(double s, int order, double b[4]) {
  switch (order) {
    case 0: {
      const double u = 1.0 - s, s2 = s * s, s3 = s2 * s;
      b[0] = u * u * u / 6.0;
      b[1] = (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0;
      b[2] = (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0;
      b[3] = s3 / 6.0;
      return;
    }
    case 1: {
      const double u = 1.0 - s;
      b[0] = -0.5 * u * u;
      b[1] = 1.5 * s * s - 2.0 * s;
      b[2] = -1.5 * s * s + s + 0.5;
      b[3] = 0.5 * s * s;
      return;
    }
    case 2:
      b[0] = 1.0 - s;
      b[1] = 3.0 * s - 2.0;
      b[2] = -3.0 * s + 1.0;
      b[3] = s;
      return;
    case 3:
      b[0] = -1.0;
      b[1] = 3.0;
      b[2] = -3.0;
      b[3] = 1.0;
      return;
    default:
      b[0] = b[1] = b[2] = b[3] = 0.0;
  }
}

template <int Dim>
class UniformBSpline {
 public:
  static constexpr int kDegree = 3;
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Points = std::vector<Point, Eigen::aligned_allocator<Point>>;

  UniformBSpline() = default;
  UniformBSpline(Points control_points, double knot_interval)
      : q_(std::move(control_points)), dt_(knot_interval) {
    if (q_.size() < 4) throw std::invalid_argument("a cubic B-spline needs at least 4 control points");
    if (!(dt_ > 0)) throw std::invalid_argument("knot interval must be positive");
  }

  bool empty() const { return q_.empty(); }
  int size() const { return static_cast<int>(q_.size()); }
  double knot_interval() const { return dt_; }
  double duration() const { return q_.size() < 4 ? 0.0 : (static_cast<double>(q_.size()) - 3.0) * dt_; }
  const Points& control_points() const { return q_; }
  Points& control_points() { return q_; }
  // Uniform time scaling: the same curve, traversed `factor` times slower.
  void set_knot_interval(double dt) { dt_ = dt; }

  // The segment index and local parameter of time t (clamped to [0, duration]).
  void locate(double t, int* segment, double* s) const {
    const int last = size() - 4;
    const double u = std::clamp(t / dt_, 0.0, static_cast<double>(last + 1));
    int j = static_cast<int>(std::floor(u));
    if (j > last) j = last;
    *segment = j;
    *s = u - j;
  }

  // Derivative of order 0..3 with respect to time at t (clamped to [0, duration]).
  Point evaluate(double t, int order = 0) const {
    int j;
    double s, b[4];
    locate(t, &j, &s);
    cubic_basis(s, order, b);
    Point p = b[0] * q_[j] + b[1] * q_[j + 1] + b[2] * q_[j + 2] + b[3] * q_[j + 3];
    return order == 0 ? p : Point(p / std::pow(dt_, order));
  }

  // Control points of the order-th time derivative (a B-spline of degree 3 - order whose values
  // the derivative stays within the convex hull of).
  Points derivative_control_points(int order) const {
    Points d = q_;
    for (int k = 0; k < order; ++k) {
      for (std::size_t i = 0; i + 1 < d.size(); ++i) d[i] = (d[i + 1] - d[i]) / dt_;
      if (!d.empty()) d.pop_back();
    }
    return d;
  }

  // Largest norm of the order-th derivative's control points: an upper bound of the norm of
  // that derivative over the whole curve.
  double derivative_bound(int order) const {
    double m = 0.0;
    for (const Point& p : derivative_control_points(order)) m = std::max(m, p.norm());
    return m;
  }

 private:
  Points q_;
  double dt_ = 1.0;
};

using PositionSpline = UniformBSpline<3>;
using YawSpline = UniformBSpline<1>;

}  // namespace semx::controller
