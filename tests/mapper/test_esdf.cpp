// The ESDF window against brute force.
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <random>

#include "mapper_test_util.hpp"

namespace semx::mapper {
namespace {

// Brute-force value of one voxel, by the definition in esdf.hpp.
float brute_distance(const map::StateGrid& g, const map::EsdfGrid& e, int x, int y, int z) {
  auto obstacle = [&](int i, int j, int k) {
    const map::VoxelState s = g.state(e.origin + map::VoxelKey{i, j, k});
    return s == map::VoxelState::kOccupied || (e.unknown_as_occupied && s == map::VoxelState::kUnknown);
  };
  const bool inside = obstacle(x, y, z);
  double best = 1e30;
  for (int k = 0; k < e.nz; ++k)
    for (int j = 0; j < e.ny; ++j)
      for (int i = 0; i < e.nx; ++i)
        if (obstacle(i, j, k) != inside)
          best = std::min(best, double((i - x) * (i - x) + (j - y) * (j - y) + (k - z) * (k - z)));
  const double d = (std::sqrt(best) - 0.5) * e.resolution;
  const double clamped = std::min(d, e.max_distance);
  return static_cast<float>(inside ? -clamped : clamped);
}

TEST(Esdf, MatchesBruteForceOnRandomScenes) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (const bool unknown_as_occupied : {true, false}) {
    for (int trial = 0; trial < 3; ++trial) {
      EsdfParams p;
      p.window = {2.0, 1.6, 0.8};
      p.max_distance = 0.6;
      p.unknown_as_occupied = unknown_as_occupied;
      EsdfBuilder builder(p, 0.1);
      const Eigen::Vector3d center(0.3, -0.45, 1.0);
      const map::VoxelKey o = builder.window_origin(center);
      map::StateGrid g(0.1);
      // Mostly free with scattered obstacles and an unknown corner; a little margin outside the
      // window shows that outside voxels are ignored.
      for (int z = -1; z <= 8; ++z)
        for (int y = -1; y <= 16; ++y)
          for (int x = -1; x <= 20; ++x) {
            const double r = u(rng);
            const map::VoxelKey k = o + map::VoxelKey{x, y, z};
            if (x < 4 && y < 4 && z < 3) continue;  // unknown
            g.set_state(k, r < 0.04 ? map::VoxelState::kOccupied : map::VoxelState::kFree);
          }
      ASSERT_TRUE(builder.update(g, center, map::KeyBox(), 7));
      const map::EsdfGrid& e = builder.grid();
      ASSERT_EQ(e.nx, 20);
      ASSERT_EQ(e.ny, 16);
      ASSERT_EQ(e.nz, 8);
      EXPECT_EQ(e.origin, o);
      EXPECT_EQ(e.map_seq, 7);
      for (int z = 0; z < e.nz; ++z)
        for (int y = 0; y < e.ny; ++y)
          for (int x = 0; x < e.nx; ++x)
            ASSERT_NEAR(e.distance[e.index(x, y, z)], brute_distance(g, e, x, y, z), 1e-5)
                << x << " " << y << " " << z << " unknown_as_occupied " << unknown_as_occupied;
    }
  }
}

// Inside obstacles the builder searches around the voxels deeper than one layer, or runs the
// full transform when they are too many: both against brute force, and against each other.
TEST(Esdf, InsideThickObstaclesSearchAndTransformMatchBruteForce) {
  struct Scene {
    bool unknown_as_occupied;
    bool random_boxes;      // else a thick slab, a block and an L of bars
    double budget;          // search visits per window voxel (0: the transform)
    bool expect_transform;  // what the builder should end up running
  };
  // An ample budget searches even the slab; the default one gives way to the transform for the
  // unknown half, and so does none at all. Random overlapping boxes put the nearest free voxel
  // off the axes, where a search stopped too early would return a farther one.
  const double ample = 1e4, none = 0.0, fallback = EsdfBuilder::kDefaultSearchBudget;
  const Scene scenes[] = {{false, false, ample, false},  {true, false, ample, false},
                          {true, false, fallback, true}, {false, false, none, true},
                          {false, true, ample, false},   {false, true, ample, false},
                          {false, true, ample, false}};
  std::mt19937 rng(11);
  for (const Scene& sc : scenes) {
    EsdfParams p;
    p.window = {2.0, 1.6, 0.8};
    // Slab scenes: its deepest voxels are clamped, shallower ones exact.
    p.max_distance = sc.random_boxes ? 1.0 : 0.35;
    p.unknown_as_occupied = sc.unknown_as_occupied;
    EsdfBuilder builder(p, 0.1);
    builder.set_inside_search_budget(sc.budget);
    const Eigen::Vector3d center(0.3, -0.45, 1.0);
    const map::VoxelKey o = builder.window_origin(center);
    std::vector<std::array<int, 6>> boxes;
    std::uniform_int_distribution<int> corner(-3, 17), size(3, 10);
    for (int b = 0; sc.random_boxes && b < 24; ++b) {
      const int x = corner(rng), y = corner(rng), z = corner(rng) / 2;
      boxes.push_back({x, y, z, x + size(rng), y + size(rng), z + size(rng) / 2});
    }
    map::StateGrid g(0.1);
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 20; ++x) {
          const map::VoxelKey k = o + map::VoxelKey{x, y, z};
          bool occupied = false;
          if (sc.random_boxes) {
            for (const auto& b : boxes)
              occupied |= x >= b[0] && y >= b[1] && z >= b[2] && x < b[3] && y < b[4] && z < b[5];
          } else {
            // A slab 9 voxels thick on the window's low-x face (the face is not free space, so its
            // voxels there are 9 deep), a 3x3x3 block, an L of two thick bars, and, with unknown
            // as obstacle, the window's top half unknown.
            const bool slab = x < 9;
            const bool block = x >= 12 && x < 15 && y >= 5 && y < 8 && z >= 2 && z < 5;
            const bool bar = (x >= 16 && y >= 10 && z < 3) || (x >= 16 && y >= 13 && z < 6);
            if (sc.unknown_as_occupied && z >= 4) continue;
            occupied = slab || block || bar;
          }
          g.set_state(k, occupied ? map::VoxelState::kOccupied : map::VoxelState::kFree);
        }
    ASSERT_TRUE(builder.update(g, center, map::KeyBox(), 1));
    EXPECT_EQ(builder.last_inside_transform(), sc.expect_transform) << "budget " << sc.budget;
    const map::EsdfGrid& e = builder.grid();
    int deep = 0;
    for (int z = 0; z < e.nz; ++z)
      for (int y = 0; y < e.ny; ++y)
        for (int x = 0; x < e.nx; ++x) {
          const float want = brute_distance(g, e, x, y, z);
          deep += want < -0.06f;
          ASSERT_NEAR(e.distance[e.index(x, y, z)], want, 1e-5)
              << x << " " << y << " " << z << " budget " << sc.budget << " unknown "
              << sc.unknown_as_occupied;
        }
    EXPECT_GT(deep, 50) << "random " << sc.random_boxes;  // the scene does test deep voxels
  }
}

// The squared transform is exact: every cell's value equals the brute-force squared distance to
// the nearest site, to the last bit (the envelope is kept in integers), on grids with sparse and
// dense sites, long lines on each axis, and lines and grids without any site.
TEST(Esdf, SquaredTransformEqualsBruteForceExactly) {
  std::mt19937 rng(5);
  const int shapes[][3] = {{40, 30, 12}, {120, 3, 2}, {3, 110, 4}, {5, 4, 100}, {17, 19, 23}};
  EdtWorkspace work;
  for (const auto& shape : shapes) {
    const int nx = shape[0], ny = shape[1], nz = shape[2];
    const size_t n = static_cast<size_t>(nx) * ny * nz;
    for (const double density : {0.0, 0.002, 0.03, 0.4}) {
      std::bernoulli_distribution site(density);
      std::vector<uint8_t> grid(n);
      std::vector<std::array<int, 3>> sites;
      for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            const bool s = site(rng);
            grid[x + static_cast<size_t>(nx) * (y + static_cast<size_t>(ny) * z)] = s ? 1 : 0;
            if (s) sites.push_back({x, y, z});
          }
      std::vector<float> out(n);
      squared_edt(grid.data(), 1, nx, ny, nz, out.data(), work);
      for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            const float got = out[x + static_cast<size_t>(nx) * (y + static_cast<size_t>(ny) * z)];
            if (sites.empty()) {
              ASSERT_GE(got, kEdtInfinity);
              continue;
            }
            int64_t best = std::numeric_limits<int64_t>::max();
            for (const auto& p : sites) {
              const int64_t dx = p[0] - x, dy = p[1] - y, dz = p[2] - z;
              best = std::min(best, dx * dx + dy * dy + dz * dz);
            }
            ASSERT_EQ(got, static_cast<float>(best)) << nx << "x" << ny << "x" << nz << " density " << density
                                                     << " at " << x << "," << y << "," << z;
          }
    }
  }
}

TEST(Esdf, InterpolationAndGradientPointAwayFromAnObstacle) {
  EsdfParams p;
  p.window = {3.0, 3.0, 3.0};
  p.max_distance = 5.0;
  p.unknown_as_occupied = false;
  EsdfBuilder builder(p, 0.1);
  map::StateGrid g(0.1);
  g.set_state({0, 0, 0}, map::VoxelState::kOccupied);
  builder.update(g, Eigen::Vector3d(0.05, 0.05, 0.05), map::KeyBox(), 1);
  const map::EsdfGrid& e = builder.grid();
  double d;
  Eigen::Vector3d grad;
  // At a voxel centre the interpolation is the voxel's value.
  ASSERT_TRUE(e.interpolate(Eigen::Vector3d(0.55, 0.05, 0.05), &d, &grad));
  EXPECT_NEAR(d, 0.45, 1e-6);
  EXPECT_NEAR(grad.x(), 1.0, 1e-6);
  // Between centres, the gradient matches finite differences of the interpolation.
  const Eigen::Vector3d p0(0.43, 0.37, -0.21);
  ASSERT_TRUE(e.interpolate(p0, &d, &grad));
  const double h = 1e-5;
  for (int a = 0; a < 3; ++a) {
    double dp, dm;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[a] = h;
    ASSERT_TRUE(e.interpolate(p0 + step, &dp, nullptr));
    ASSERT_TRUE(e.interpolate(p0 - step, &dm, nullptr));
    EXPECT_NEAR(grad[a], (dp - dm) / (2 * h), 1e-4) << a;
  }
  EXPECT_GT(grad.dot(p0 - Eigen::Vector3d(0.05, 0.05, 0.05)), 0.0) << "the gradient points away";
  // Inside the obstacle the value is negative.
  float v;
  ASSERT_TRUE(e.voxel_distance({0, 0, 0}, &v));
  EXPECT_FLOAT_EQ(v, -0.05f);
  EXPECT_FALSE(e.interpolate(Eigen::Vector3d(10, 0, 0), &d, nullptr));
  EXPECT_FALSE(e.interpolate(Eigen::Vector3d(std::nan(""), 0, 0), &d, nullptr));
}

TEST(Esdf, RecomputesOnlyWhenTheWindowMovesOrSomethingInsideChanged) {
  EsdfParams p;
  p.window = {2.0, 2.0, 1.0};
  EsdfBuilder builder(p, 0.1);
  map::StateGrid g(0.1);
  const Eigen::Vector3d c(1.0, 1.0, 1.0);
  EXPECT_TRUE(builder.update(g, c, map::KeyBox(), 1));
  EXPECT_FALSE(builder.update(g, c, map::KeyBox(), 2));
  EXPECT_EQ(builder.grid().map_seq, 2) << "still valid for the newer map";
  map::KeyBox far;
  far.include({500, 500, 500});
  EXPECT_FALSE(builder.update(g, c, far, 3));
  map::KeyBox near;
  near.include(map::KeyMath(0.1).key(c));
  EXPECT_TRUE(builder.update(g, c, near, 4));
  EXPECT_TRUE(builder.update(g, c + Eigen::Vector3d(0.1, 0, 0), map::KeyBox(), 5));
  EXPECT_FALSE(builder.update(g, Eigen::Vector3d(std::nan(""), 0, 0), near, 6));
}

TEST(Esdf, MapperKeepsTheWindowAroundTheVehicle) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  const auto frames = test::room_frames(4, cam, 4);
  for (const auto& f : frames) {
    mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
    ASSERT_TRUE(mapper.update_esdf(f.pose.translation()));
  }
  const map::EsdfGrid& e = mapper.esdf();
  EXPECT_EQ(e.nx, 100);
  EXPECT_EQ(e.ny, 100);
  EXPECT_EQ(e.nz, 30);
  EXPECT_EQ(e.map_seq, mapper.seq());
  // A metre in front of the camera is seen free space, over half a metre from anything the
  // last frame did not see (which counts as an obstacle).
  double d;
  ASSERT_TRUE(e.interpolate(frames.back().pose * Eigen::Vector3d(0, 0, 1.0), &d));
  EXPECT_GT(d, 0.3);
  // Points inside the table are inside an obstacle.
  ASSERT_TRUE(e.interpolate(Eigen::Vector3d(1.6, 1.4, 0.5), &d));
  EXPECT_LT(d, 0.0);
  // Nothing changed: no recomputation.
  EXPECT_FALSE(mapper.update_esdf(frames.back().pose.translation()));
}

}  // namespace
}  // namespace semx::mapper
