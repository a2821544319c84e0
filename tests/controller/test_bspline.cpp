// Uniform cubic B-spline: values, derivatives, and the convex-hull bounds the limits rely on.
#include <gtest/gtest.h>

#include <random>

#include "semx/controller/bspline.hpp"

using namespace semx::controller;

namespace {

PositionSpline random_spline(std::mt19937_64& rng, int n, double dt) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  PositionSpline::Points q;
  for (int i = 0; i < n; ++i) q.emplace_back(u(rng), u(rng), u(rng));
  return PositionSpline(q, dt);
}

}  // namespace

TEST(BSpline, BasisIsAPartitionOfUnityAndDerivativesSumToZero) {
  for (double s = 0.0; s <= 1.0; s += 0.05) {
    double b[4];
    cubic_basis(s, 0, b);
    EXPECT_NEAR(b[0] + b[1] + b[2] + b[3], 1.0, 1e-12);
    for (double x : b) EXPECT_GE(x, -1e-15);
    for (int order = 1; order <= 3; ++order) {
      cubic_basis(s, order, b);
      EXPECT_NEAR(b[0] + b[1] + b[2] + b[3], 0.0, 1e-12) << "order " << order;
    }
  }
}

TEST(BSpline, ReproducesStraightLinesAtConstantSpeed) {
  // Control points Q_i = a + v·(i-1)·dt trace p(t) = a + v·t exactly.
  const Eigen::Vector3d a(1, -2, 0.5), v(0.3, 0.4, -0.1);
  const double dt = 0.2;
  PositionSpline::Points q;
  for (int i = 0; i < 10; ++i) q.push_back(a + v * (i - 1) * dt);
  const PositionSpline s(q, dt);
  EXPECT_NEAR(s.duration(), 7 * dt, 1e-12);
  for (double t = 0; t <= s.duration(); t += 0.013) {
    EXPECT_LT((s.evaluate(t) - (a + v * t)).norm(), 1e-12);
    EXPECT_LT((s.evaluate(t, 1) - v).norm(), 1e-12);
    EXPECT_LT(s.evaluate(t, 2).norm(), 1e-10);
  }
}

TEST(BSpline, ValueAtKnotsIsTheOneFourOneAverage) {
  std::mt19937_64 rng(1);
  const PositionSpline s = random_spline(rng, 9, 0.3);
  const auto& q = s.control_points();
  for (int j = 0; j + 3 < s.size(); ++j) {
    const Eigen::Vector3d expect = (q[j] + 4 * q[j + 1] + q[j + 2]) / 6.0;
    EXPECT_LT((s.evaluate(j * 0.3) - expect).norm(), 1e-12) << j;
    const Eigen::Vector3d v = (q[j + 2] - q[j]) / (2 * 0.3);
    EXPECT_LT((s.evaluate(j * 0.3, 1) - v).norm(), 1e-9) << j;
  }
}

TEST(BSpline, DerivativesMatchFiniteDifferences) {
  std::mt19937_64 rng(2);
  const PositionSpline s = random_spline(rng, 12, 0.25);
  const double h = 1e-6;
  for (double t = 0.01; t < s.duration() - 0.01; t += 0.037) {
    const Eigen::Vector3d fd1 = (s.evaluate(t + h) - s.evaluate(t - h)) / (2 * h);
    EXPECT_LT((fd1 - s.evaluate(t, 1)).norm(), 1e-5) << t;
    if (std::abs(std::remainder(t, 0.25)) < 1e-3) continue;  // jerk jumps at knots
    const Eigen::Vector3d fd2 = (s.evaluate(t + h, 1) - s.evaluate(t - h, 1)) / (2 * h);
    EXPECT_LT((fd2 - s.evaluate(t, 2)).norm(), 1e-4) << t;
    const Eigen::Vector3d fd3 = (s.evaluate(t + h, 2) - s.evaluate(t - h, 2)) / (2 * h);
    EXPECT_LT((fd3 - s.evaluate(t, 3)).norm(), 1e-3) << t;
  }
}

TEST(BSpline, IsContinuousInPositionVelocityAndAccelerationAcrossKnots) {
  std::mt19937_64 rng(3);
  const PositionSpline s = random_spline(rng, 10, 0.4);
  for (int j = 1; j < s.size() - 3; ++j) {
    const double t = j * 0.4, e = 1e-9;
    for (int order = 0; order <= 2; ++order) {
      EXPECT_LT((s.evaluate(t - e, order) - s.evaluate(t + e, order)).norm(), 1e-6) << j << " " << order;
    }
  }
}

TEST(BSpline, DerivativeBoundsHoldEverywhere) {
  std::mt19937_64 rng(4);
  for (int k = 0; k < 20; ++k) {
    const PositionSpline s = random_spline(rng, 8 + k, 0.1 + 0.05 * k);
    const double vb = s.derivative_bound(1), ab = s.derivative_bound(2);
    for (double t = 0; t <= s.duration(); t += s.duration() / 997) {
      EXPECT_LE(s.evaluate(t, 1).norm(), vb * (1 + 1e-12));
      EXPECT_LE(s.evaluate(t, 2).norm(), ab * (1 + 1e-12));
    }
  }
}

TEST(BSpline, TimeScalingSlowsTheSameCurve) {
  std::mt19937_64 rng(5);
  PositionSpline s = random_spline(rng, 10, 0.2);
  const PositionSpline before = s;
  s.set_knot_interval(0.5);
  EXPECT_NEAR(s.duration(), before.duration() * 2.5, 1e-12);
  EXPECT_LT((s.evaluate(1.0 * 2.5) - before.evaluate(1.0)).norm(), 1e-12);
  EXPECT_LT((s.evaluate(1.0 * 2.5, 1) * 2.5 - before.evaluate(1.0, 1)).norm(), 1e-9);
  EXPECT_NEAR(s.derivative_bound(2) * 6.25, before.derivative_bound(2), 1e-9);
}

TEST(BSpline, ClampsTimeAndRejectsTooFewPoints) {
  std::mt19937_64 rng(6);
  const PositionSpline s = random_spline(rng, 6, 0.3);
  EXPECT_LT((s.evaluate(-1.0) - s.evaluate(0.0)).norm(), 1e-12);
  EXPECT_LT((s.evaluate(100.0) - s.evaluate(s.duration())).norm(), 1e-12);
  PositionSpline::Points three(3, Eigen::Vector3d::Zero());
  EXPECT_THROW(PositionSpline(three, 0.1), std::invalid_argument);
  EXPECT_THROW(PositionSpline(PositionSpline::Points(4, Eigen::Vector3d::Zero()), 0.0),
               std::invalid_argument);
}
