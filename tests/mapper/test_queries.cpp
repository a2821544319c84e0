// The map queries every consumer uses (map::StateGrid, shared by the mapper's map and its mirrors).
#include <gtest/gtest.h>

#include <random>

#include "mapper_test_util.hpp"

namespace semx::mapper {
namespace {

constexpr map::VoxelState U = map::VoxelState::kUnknown, F = map::VoxelState::kFree,
                          O = map::VoxelState::kOccupied;

TEST(Queries, FrontierIsUnknownWithAFreeFaceNeighbour) {
  map::StateGrid g(0.1);
  g.set_state({0, 0, 0}, F);
  EXPECT_TRUE(g.is_frontier({1, 0, 0}));
  EXPECT_TRUE(g.is_frontier({0, 0, -1}));
  EXPECT_FALSE(g.is_frontier({1, 1, 0})) << "edge neighbours do not count";
  EXPECT_FALSE(g.is_frontier({0, 0, 0})) << "a free voxel is not a frontier";
  EXPECT_FALSE(g.is_frontier({2, 0, 0}));
  EXPECT_FALSE(g.is_surface({1, 0, 0})) << "no occupied neighbour";
  g.set_state({1, 0, 1}, O);
  EXPECT_TRUE(g.is_surface({1, 0, 0}));
  EXPECT_FALSE(g.is_surface({1, 0, 1})) << "occupied, not unknown";
  EXPECT_FALSE(g.is_surface({2, 0, 1})) << "next to occupied but not to free";
  g.set_state({1, 0, 0}, O);
  EXPECT_FALSE(g.is_frontier({1, 0, 0}));
}

TEST(Queries, FrontierCountMatchesBruteForceAcrossBlockBorders) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    map::StateGrid g(0.1);
    std::uniform_real_distribution<double> u(0, 1);
    // A region straddling block borders (blocks are 16 voxels), sparse enough to leave unknown
    // voxels in unallocated blocks next to free ones.
    const int lo = -16, hi = 15;  // exactly blocks -1..0: the neighbours outside are in unallocated blocks
    for (int z = lo; z <= hi; ++z)
      for (int y = lo; y <= hi; ++y)
        for (int x = lo; x <= hi; ++x) {
          const double r = u(rng);
          if (r < 0.25)
            g.set_state({x, y, z}, F);
          else if (r < 0.32)
            g.set_state({x, y, z}, O);
        }
    int64_t brute = 0;
    for (int z = lo - 1; z <= hi + 1; ++z)
      for (int y = lo - 1; y <= hi + 1; ++y)
        for (int x = lo - 1; x <= hi + 1; ++x) {
          if (g.state(map::VoxelKey{x, y, z}) != U) continue;
          bool f = false;
          for (const map::VoxelKey& d : map::kFaceNeighbours) f |= g.state(map::VoxelKey{x, y, z} + d) == F;
          brute += f;
        }
    EXPECT_EQ(g.count_frontiers(), brute) << "trial " << trial;
  }
}

TEST(Queries, RayVisibilityStopsAtObstacles) {
  map::StateGrid g(0.1);
  for (int x = 0; x < 20; ++x) g.set_state({x, 0, 0}, F);
  const Eigen::Vector3d a(0.05, 0.05, 0.05), b(1.95, 0.05, 0.05);
  EXPECT_TRUE(g.is_visible(a, b));
  g.set_state({19, 0, 0}, O);
  EXPECT_TRUE(g.is_visible(a, b)) << "the target voxel itself may be occupied (a surface is seen)";
  g.set_state({10, 0, 0}, O);
  EXPECT_FALSE(g.is_visible(a, b));
  EXPECT_FALSE(g.is_visible(b, a));
  g.set_state({10, 0, 0}, U);
  EXPECT_TRUE(g.is_visible(a, b));
  EXPECT_FALSE(g.is_visible(a, b, /*unknown_blocks=*/true));
  EXPECT_FALSE(g.is_visible(a, Eigen::Vector3d(std::nan(""), 0, 0)));
  // A diagonal line of sight passes through the voxels it touches, and not around them.
  map::StateGrid d(0.1);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) d.set_state({i, j, 0}, F);
  d.set_state({5, 5, 0}, O);
  EXPECT_FALSE(d.is_visible({0.05, 0.05, 0.05}, {0.95, 0.95, 0.05}));
  EXPECT_TRUE(d.is_visible({0.05, 0.05, 0.05}, {0.95, 0.35, 0.05}));
}

TEST(Queries, TraversalVisitsA6ConnectedPathFromStartToEnd) {
  const map::KeyMath km(0.1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    std::vector<map::VoxelKey> path;
    ASSERT_TRUE(map::traverse_segment(km, a, b, [&](const map::VoxelKey& k) {
      path.push_back(k);
      return true;
    }));
    ASSERT_EQ(path.front(), km.key(a));
    ASSERT_EQ(path.back(), km.key(b));
    for (size_t j = 1; j < path.size(); ++j) {
      const map::VoxelKey d = path[j] - path[j - 1];
      ASSERT_EQ(std::abs(d.x) + std::abs(d.y) + std::abs(d.z), 1);
    }
    // Every voxel on the path is within a voxel diagonal of the segment.
    for (const map::VoxelKey& k : path) {
      const Eigen::Vector3d c = km.center(k);
      const double t = std::clamp((c - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      ASSERT_LE((a + t * (b - a) - c).norm(), 0.0867);
    }
  }
}

TEST(Queries, BoxCollisionCountsOverlappingVoxelsOnly) {
  map::StateGrid g(0.1);
  for (int z = -5; z < 5; ++z)
    for (int y = -5; y < 5; ++y)
      for (int x = -5; x < 40; ++x) g.set_state({x, y, z}, F);
  g.set_state({20, 0, 0}, O);  // covers [2.0, 2.1) x [0, 0.1) x [0, 0.1)
  const Eigen::Vector3d half(0.25, 0.25, 0.15);
  EXPECT_FALSE(
      g.box_collides(Eigen::Vector3d(1.0, 0.05, 0.05) - half, Eigen::Vector3d(1.0, 0.05, 0.05) + half));
  EXPECT_TRUE(
      g.box_collides(Eigen::Vector3d(2.0, 0.05, 0.05) - half, Eigen::Vector3d(2.0, 0.05, 0.05) + half));
  // Touching the obstacle's face is not a collision; overlapping it by a hair is.
  EXPECT_FALSE(g.box_collides({1.5, -0.2, -0.2}, {2.0, 0.2, 0.2}));
  EXPECT_TRUE(g.box_collides({1.5, -0.2, -0.2}, {2.001, 0.2, 0.2}));
  // Unknown space beyond x = 4 m.
  EXPECT_TRUE(g.box_collides({3.8, 0, 0}, {4.1, 0.1, 0.1}));
  EXPECT_FALSE(g.box_collides({3.8, 0, 0}, {4.1, 0.1, 0.1}, /*unknown_is_occupied=*/false));
  // Degenerate or invalid boxes collide.
  EXPECT_TRUE(g.box_collides({1, 0, 0}, {1, 0.1, 0.1}));
  EXPECT_TRUE(g.box_collides({std::nan(""), 0, 0}, {1, 0.1, 0.1}));
}

TEST(Queries, MirrorAndMapAnswerTheSame) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  map::MapMirror mirror(0.1);
  for (const auto& f : test::room_frames(6, cam, 6)) {
    const FrameResult r = mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
    ASSERT_EQ(mirror.apply(r.delta), map::MapMirror::DeltaResult::kApplied);
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-0.5, 6.5), y(-0.5, 5.5), z(-0.3, 3.0);
  const OccupancyMap& map = mapper.map();
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d a(x(rng), y(rng), z(rng)), b(x(rng), y(rng), z(rng));
    const map::VoxelKey k = map.keys().key(a);
    ASSERT_EQ(mirror.state(k), map.state(k));
    ASSERT_EQ(mirror.is_frontier(k), map.is_frontier(k));
    ASSERT_EQ(mirror.is_surface(k), map.is_surface(k));
    ASSERT_EQ(mirror.is_visible(a, b), map.is_visible(a, b));
    ASSERT_EQ(mirror.is_visible(a, b, true), map.is_visible(a, b, true));
    const Eigen::Vector3d half(0.25, 0.25, 0.15);
    ASSERT_EQ(mirror.box_collides(a - half, a + half), map.box_collides(a - half, a + half));
  }
  EXPECT_EQ(mirror.count_frontiers(), map.count_frontiers());
  EXPECT_GT(map.count_frontiers(), 100);
}

}  // namespace
}  // namespace semx::mapper
