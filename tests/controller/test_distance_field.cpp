// The dense ESDF grid: trilinear values and gradients against analytic fields, borders, the
// outside policy and the Lipschitz bound the clearance check pads with.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "fields.hpp"
#include "semx/controller/grid_distance_field.hpp"

using namespace semx::controller;
using semx::controller::test::sample_grid;

TEST(GridDistanceField, ReproducesLinearFieldsAndTheirGradientExactly) {
  // Trilinear interpolation is exact for (multi)linear functions between cell centres.
  const Eigen::Vector3d a(0.3, -0.7, 0.2);
  const auto f = [&](const Eigen::Vector3d& p) { return a.dot(p) + 0.5; };
  const Eigen::Vector3d origin(-1.0, -2.0, 0.0);
  const double res = 0.1;
  const GridDistanceField g = sample_grid(f, origin, res, 30, 40, 20);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    // Inside the hull of the cell centres.
    const Eigen::Vector3d p =
        origin + Eigen::Vector3d(0.05 + 2.9 * u(rng), 0.05 + 3.9 * u(rng), 0.05 + 1.9 * u(rng));
    Eigen::Vector3d grad;
    const double d = g.distance(p, &grad);
    EXPECT_NEAR(d, f(p), 2e-6);  // float storage
    EXPECT_LT((grad - a).norm(), 1e-4);
  }
}

TEST(GridDistanceField, ApproximatesASphereAndItsGradient) {
  const Eigen::Vector3d c(1.0, 1.0, 1.0);
  const double r = 0.5;
  const auto f = [&](const Eigen::Vector3d& p) { return (p - c).norm() - r; };
  const GridDistanceField g = sample_grid(f, Eigen::Vector3d::Zero(), 0.05, 40, 40, 40);
  std::mt19937_64 rng(2);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    Eigen::Vector3d dir(n(rng), n(rng), n(rng));
    dir.normalize();
    const double radius = 0.4 + 0.5 * (i % 100) / 100.0;
    const Eigen::Vector3d p = c + radius * dir;
    Eigen::Vector3d grad;
    const double d = g.distance(p, &grad);
    EXPECT_NEAR(d, f(p), 0.01) << p.transpose();
    EXPECT_GT(grad.dot(dir), 0.93) << "gradient points away from the centre";
    EXPECT_NEAR(grad.norm(), 1.0, 0.07);
  }
}

TEST(GridDistanceField, GradientIsTheDerivativeOfTheInterpolant) {
  const auto f = [](const Eigen::Vector3d& p) {
    return std::sin(3 * p.x()) * std::cos(2 * p.y()) + 0.3 * p.z() * p.z();
  };
  const GridDistanceField g = sample_grid(f, Eigen::Vector3d(-1, -1, -1), 0.1, 20, 20, 20);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.9, 0.9);
  const double h = 1e-7;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    Eigen::Vector3d grad;
    g.distance(p, &grad);
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d dp = Eigen::Vector3d::Zero();
      dp[a] = h;
      const double fd = (g.distance(p + dp) - g.distance(p - dp)) / (2 * h);
      EXPECT_NEAR(fd, grad[a], 1e-4) << "axis " << a << " at " << p.transpose();
    }
  }
}

TEST(GridDistanceField, IndexLayoutMatchesEsdfLocal) {
  // distance[ix + nx*(iy + ny*iz)] is the cell whose centre is origin + (i + 0.5)·res.
  const int nx = 4, ny = 3, nz = 2;
  std::vector<float> v(nx * ny * nz);
  for (int i = 0; i < nx * ny * nz; ++i) v[i] = static_cast<float>(i);
  const Eigen::Vector3d origin(10, 20, 30);
  const GridDistanceField g(origin, 0.5, nx, ny, nz, v, 100.0, OutsideWindow::kFree);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const Eigen::Vector3d centre =
            origin + (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * 0.5;
        EXPECT_FLOAT_EQ(g.distance(centre), static_cast<float>(x + nx * (y + ny * z)));
      }
}

TEST(GridDistanceField, BorderValuesExtendHalfACellAndOutsideFollowsThePolicy) {
  const auto f = [](const Eigen::Vector3d& p) { return p.x(); };
  const GridDistanceField free =
      sample_grid(f, Eigen::Vector3d::Zero(), 0.1, 10, 10, 10, 2.0, OutsideWindow::kFree);
  const GridDistanceField obst =
      sample_grid(f, Eigen::Vector3d::Zero(), 0.1, 10, 10, 10, 2.0, OutsideWindow::kObstacle);
  Eigen::Vector3d g;
  // Between the face and the first centre: the first centre's value, no slope along x.
  EXPECT_NEAR(free.distance(Eigen::Vector3d(0.02, 0.5, 0.5), &g), 0.05, 1e-6);
  EXPECT_EQ(g.x(), 0.0);
  EXPECT_NEAR(free.distance(Eigen::Vector3d(0.99, 0.5, 0.5)), 0.95, 1e-6);
  EXPECT_EQ(free.distance(Eigen::Vector3d(-0.01, 0.5, 0.5), &g), 2.0);
  EXPECT_EQ(g.norm(), 0.0);
  EXPECT_EQ(free.distance(Eigen::Vector3d(0.5, 0.5, 1.2)), 2.0);
  EXPECT_EQ(obst.distance(Eigen::Vector3d(-0.01, 0.5, 0.5)), -2.0);
  EXPECT_EQ(obst.distance(Eigen::Vector3d(0.5, 0.5, 0.5)), free.distance(Eigen::Vector3d(0.5, 0.5, 0.5)));
  EXPECT_EQ(free.distance(Eigen::Vector3d(NAN, 0.5, 0.5)), -2.0);  // nowhere is never safe
}

TEST(GridDistanceField, LipschitzBoundsTheSlopeEverywhere) {
  const auto f = [](const Eigen::Vector3d& p) { return std::abs(p.x() - 0.5) + 0.5 * std::abs(p.y() - 0.3); };
  const GridDistanceField g = sample_grid(f, Eigen::Vector3d::Zero(), 0.1, 10, 10, 10);
  EXPECT_GT(g.lipschitz(), 1.0);
  EXPECT_LT(g.lipschitz(), 1.2);  // ≈ |(1, 0.5, 0)|
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    Eigen::Vector3d grad;
    g.distance(Eigen::Vector3d(u(rng), u(rng), u(rng)), &grad);
    EXPECT_LE(grad.norm(), g.lipschitz() + 1e-9);
  }
}

// The bound is built from the largest neighbour difference per axis, over flat runs of the
// array; a difference that straddles a row or a plane (not neighbours) must not count, and thin
// grids (one cell along an axis, runs shorter than the vector width) must be handled.
TEST(GridDistanceField, LipschitzIsTheLargestNeighbourDifferencePerAxis) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const int sizes[][3] = {{1, 1, 1}, {1, 5, 3}, {7, 1, 2}, {9, 3, 1}, {17, 13, 5}, {100, 100, 30}};
  for (const auto& s : sizes) {
    const int nx = s[0], ny = s[1], nz = s[2];
    std::vector<float> v(static_cast<std::size_t>(nx) * ny * nz);
    for (float& x : v) x = u(rng);
    // A row's last cell far above the rest: the step from it to the next row's first cell is not
    // a neighbour difference and must not count.
    v[nx - 1] = 50.0f;
    const auto at = [&](int x, int y, int z) { return v[x + static_cast<std::size_t>(nx) * (y + ny * z)]; };
    double dmax[3] = {0, 0, 0};
    for (int z = 0; z < nz; ++z) {
      for (int y = 0; y < ny; ++y) {
        for (int x = 0; x < nx; ++x) {
          if (x + 1 < nx) dmax[0] = std::max<double>(dmax[0], std::abs(at(x + 1, y, z) - at(x, y, z)));
          if (y + 1 < ny) dmax[1] = std::max<double>(dmax[1], std::abs(at(x, y + 1, z) - at(x, y, z)));
          if (z + 1 < nz) dmax[2] = std::max<double>(dmax[2], std::abs(at(x, y, z + 1) - at(x, y, z)));
        }
      }
    }
    const double want = Eigen::Vector3d(dmax[0], dmax[1], dmax[2]).norm() / 0.1;
    const GridDistanceField g(Eigen::Vector3d::Zero(), 0.1, nx, ny, nz, v, 3.0, OutsideWindow::kFree);
    EXPECT_DOUBLE_EQ(g.lipschitz(), want) << nx << " x " << ny << " x " << nz;
  }
}

TEST(GridDistanceField, RejectsInconsistentSizes) {
  EXPECT_THROW(GridDistanceField(Eigen::Vector3d::Zero(), 0.1, 2, 2, 2, std::vector<float>(7), 1,
                                 OutsideWindow::kFree),
               std::invalid_argument);
  EXPECT_THROW(GridDistanceField(Eigen::Vector3d::Zero(), 0.0, 2, 2, 2, std::vector<float>(8), 1,
                                 OutsideWindow::kFree),
               std::invalid_argument);
  EXPECT_THROW(GridDistanceField(Eigen::Vector3d::Zero(), 0.1, 0, 2, 2, std::vector<float>(0), 1,
                                 OutsideWindow::kFree),
               std::invalid_argument);
}

// The bound and every distance assume finite values; the check is a SIMD sum, which must still
// see one bad value among many, wherever it is, and whatever kind it is.
TEST(GridDistanceField, RejectsValuesThatAreNotFinite) {
  const std::vector<float> good(100 * 100 * 3, 0.7f);
  EXPECT_TRUE(GridDistanceField::all_finite(good.data(), good.size()));
  EXPECT_TRUE(GridDistanceField::all_finite(good.data(), 0));
  EXPECT_NO_THROW(
      GridDistanceField(Eigen::Vector3d::Zero(), 0.1, 100, 100, 3, good, 3.0, OutsideWindow::kFree));
  for (const float bad : {NAN, INFINITY, -INFINITY}) {
    for (const std::size_t at : {std::size_t{0}, std::size_t{5}, good.size() / 2 + 1, good.size() - 1}) {
      std::vector<float> v = good;
      v[at] = bad;
      EXPECT_FALSE(GridDistanceField::all_finite(v.data(), v.size())) << bad << " at " << at;
      EXPECT_THROW(GridDistanceField(Eigen::Vector3d::Zero(), 0.1, 100, 100, 3, v, 3.0, OutsideWindow::kFree),
                   std::invalid_argument);
    }
  }
  // The largest finite values: their differences with themselves are 0, not an overflow.
  std::vector<float> big(37, std::numeric_limits<float>::max());
  big[3] = -std::numeric_limits<float>::max();
  EXPECT_TRUE(GridDistanceField::all_finite(big.data(), big.size()));
}
