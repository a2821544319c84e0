// The geometric gain against hand-made voxel scenes: each voxel kind, occlusion, range limits,
// yaw bins, and the ray-cast evaluation against the exhaustive reference.
#include <gtest/gtest.h>

#include <cmath>

#include "planner_test_util.hpp"
#include "semx/core/angles.hpp"
#include "semx/planner/gain_evaluator.hpp"

namespace semx::planner {
namespace {

using map::VoxelKey;
using map::VoxelState;

// A short-range sensor and dense rays, so every voxel of the sector is reached.
GainConfig dense_config() {
  GainConfig c;
  c.max_range = 2.0;
  c.min_range = 0.3;
  c.rays_azimuth = 1024;
  c.rays_elevation = 160;
  return c;
}

// Free space around the origin's voxel (keys -25..24 on every axis), everything else unknown.
map::StateGrid free_scene() {
  map::StateGrid g(0.1);
  fill(g, {-25, -25, -25}, {24, 24, 24}, VoxelState::kFree);
  return g;
}

const Eigen::Vector3d kNode(0.05, 0.05, 0.05);  // centre of voxel (0, 0, 0)

// A 3x3x3 cube of unknown voxels centred on c: 26 frontier voxels (a face on free space) and a
// "normal" unknown one in the middle.
void unknown_cube(map::StateGrid& g, const VoxelKey& c) {
  fill(g, {c.x - 1, c.y - 1, c.z - 1}, {c.x + 1, c.y + 1, c.z + 1}, VoxelState::kUnknown);
}

TEST(Gain, CountsEachVoxelKindWithItsWeight) {
  map::StateGrid g = free_scene();
  unknown_cube(g, {15, -5, 0});
  // A surface voxel: unknown, a free neighbour (toward the node) and an occupied one behind it.
  g.set_state({15, 5, 0}, VoxelState::kUnknown);
  g.set_state({16, 5, 0}, VoxelState::kOccupied);

  GainEvaluator e(dense_config());
  const NodeGain r = e.evaluate(g, kNode);
  EXPECT_EQ(r.counts[0], 1);   // normal
  EXPECT_EQ(r.counts[1], 26);  // frontier
  EXPECT_EQ(r.counts[2], 1);   // surface
  EXPECT_DOUBLE_EQ(r.gain, 1 * 1 + 2 * 26 + 4 * 1);
  EXPECT_EQ(r.total_voxels(), 28);
  // Both clusters are in front (+x): the best window looks that way.
  EXPECT_LT(core::yaw_distance(r.yaw, 0.0), e.bin_width());

  const NodeGain exact = e.evaluate_exact(g, kNode);
  EXPECT_EQ(exact.counts, r.counts);
  EXPECT_EQ(exact.bin_count, r.bin_count);
}

// Ignored voxels (the unobservable ones) count for nothing, whichever block they are in: the ray
// walk reads them from the block masks, the exhaustive reference from the set.
TEST(Gain, IgnoredVoxelsCountForNothing) {
  map::StateGrid g = free_scene();
  // Cubes straddling block boundaries (blocks are 16 voxels: keys -1|0 and 15|16) and in
  // negative blocks.
  unknown_cube(g, {15, 0, 0});
  unknown_cube(g, {-15, -1, 0});
  unknown_cube(g, {0, 16, -1});
  GainEvaluator e(dense_config());
  const NodeGain all = e.evaluate(g, kNode);
  ASSERT_EQ(all.total_voxels(), 3 * 27);
  // Every other voxel of the three cubes.
  VoxelSet ignored;
  int n = 0;
  for (const VoxelKey c : {VoxelKey{15, 0, 0}, VoxelKey{-15, -1, 0}, VoxelKey{0, 16, -1}})
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
          if (++n % 2 == 0) ignored.insert({c.x + x, c.y + y, c.z + z});
  ASSERT_EQ(ignored.size(), 40u);
  e.set_ignored(&ignored);
  const NodeGain some = e.evaluate(g, kNode);
  EXPECT_EQ(some.total_voxels(), 3 * 27 - 40);
  EXPECT_EQ(e.evaluate_exact(g, kNode).bin_count, some.bin_count);
  // The cubes' middle ("normal") voxels are the 14th, 41st and 68th: only the second is kept.
  int64_t normal = 0;
  for (const auto& bin : some.bin_count) normal += bin[0];
  EXPECT_EQ(normal, 1);
  ignored.clear();
  EXPECT_EQ(e.evaluate(g, kNode).bin_count, all.bin_count);
}

TEST(Gain, WeightsAreConfigurable) {
  map::StateGrid g = free_scene();
  unknown_cube(g, {15, 0, 0});
  GainConfig c = dense_config();
  c.weight_unknown = 10;
  c.weight_frontier = 0;
  c.weight_surface = 0;
  GainEvaluator e(c);
  EXPECT_DOUBLE_EQ(e.evaluate(g, kNode).gain, 10.0);
}

TEST(Gain, OccupiedVoxelsOccludeUnknownOnesDoNot) {
  map::StateGrid g = free_scene();
  unknown_cube(g, {15, -5, 0});
  g.set_state({15, 5, 0}, VoxelState::kUnknown);
  g.set_state({16, 5, 0}, VoxelState::kOccupied);
  GainEvaluator e(dense_config());
  // A wall between the node and the cube (x key 10, y keys -9..-2).
  fill(g, {10, -9, -4}, {10, -2, 4}, VoxelState::kOccupied);
  NodeGain r = e.evaluate(g, kNode);
  EXPECT_EQ(r.counts[0], 0);
  EXPECT_EQ(r.counts[1], 0);
  EXPECT_EQ(r.counts[2], 1);
  EXPECT_EQ(e.evaluate_exact(g, kNode).counts, r.counts);

  // The same wall made of unknown voxels hides nothing (and counts itself).
  fill(g, {10, -9, -4}, {10, -2, 4}, VoxelState::kUnknown);
  r = e.evaluate(g, kNode);
  EXPECT_EQ(r.counts[0] + r.counts[1], 27 + 8 * 9);
  EXPECT_EQ(e.evaluate_exact(g, kNode).counts, r.counts);
}

TEST(Gain, RangeAndVerticalFieldOfView) {
  map::StateGrid g = free_scene();
  GainConfig c = dense_config();
  GainEvaluator e(c);
  g.set_state({1, 0, 0}, VoxelState::kUnknown);    // 0.1 m: below min_range
  g.set_state({0, 22, 0}, VoxelState::kUnknown);   // 2.2 m: beyond max_range
  g.set_state({-5, 0, 10}, VoxelState::kUnknown);  // 63° up: above the field of view
  g.set_state({-15, 0, 0}, VoxelState::kUnknown);  // 1.5 m behind: counted, best yaw pi
  const NodeGain r = e.evaluate(g, kNode);
  EXPECT_EQ(r.total_voxels(), 1);
  EXPECT_EQ(r.counts[1], 1);
  EXPECT_LT(core::yaw_distance(r.yaw, core::kPi), e.bin_width());
  EXPECT_EQ(e.evaluate_exact(g, kNode).counts, r.counts);
}

TEST(Gain, YawBinsPickTheRichestWindow) {
  map::StateGrid g = free_scene();
  unknown_cube(g, {15, 0, 0});  // +x: 53 weighted
  unknown_cube(g, {0, 15, 0});  // +y: two cubes side by side, 106
  unknown_cube(g, {-4, 15, 0});
  GainEvaluator e(dense_config());
  ASSERT_EQ(e.window_bins(), 8);  // 90° of 32 bins
  const NodeGain r = e.evaluate(g, kNode);
  EXPECT_DOUBLE_EQ(r.gain, 106.0);
  EXPECT_LT(core::yaw_distance(r.yaw, 0.5 * core::kPi + 0.13), 2 * e.bin_width());
  // Looking along +x sees the first cube only; looking at -y nothing.
  EXPECT_DOUBLE_EQ(e.gain_at_yaw(r, 0.0), 53.0);
  EXPECT_DOUBLE_EQ(e.gain_at_yaw(r, -0.5 * core::kPi), 0.0);
  // Every voxel went to the bin of its azimuth.
  for (int b = 0; b < e.bins(); ++b) {
    const auto& c = r.bin_count[static_cast<size_t>(b)];
    if (c[0] + c[1] + c[2] == 0) continue;
    const double lo = -core::kPi + b * e.bin_width(), hi = lo + e.bin_width();
    const bool plus_x = lo <= 0.1 && hi >= -0.1;
    const bool plus_y = lo <= 0.5 * core::kPi + 0.35 && hi >= 0.5 * core::kPi - 0.1;
    EXPECT_TRUE(plus_x || plus_y) << "bin " << b;
  }
}

TEST(Gain, ATurnSweepsEveryWindowItPassesTheShorterWay) {
  GainEvaluator e(GainConfig{});
  const int bins = e.bins(), w = e.window_bins();
  ASSERT_EQ(bins, 32);
  NodeGain g;
  g.bin_gain.assign(static_cast<size_t>(bins), 0.0f);
  g.bin_count.assign(static_cast<size_t>(bins), {0, 0, 0});
  for (int b = 0; b < bins; ++b) g.bin_gain[static_cast<size_t>(b)] = static_cast<float>(1 << (b % 8)) + b;
  e.finish(g);
  auto bins_sum = [&](int from, int count) {
    double s = 0;
    for (int k = 0; k < count; ++k) s += g.bin_gain[static_cast<size_t>((from + k) % bins)];
    return s;
  };
  std::vector<double> sweep;
  const int from = 4;  // the window the vehicle looks through: bins 4..11
  e.sweep_gains(g, e.window_yaw(from), sweep);
  ASSERT_EQ(sweep.size(), 32u);
  // No turn: that window. Counter-clockwise to window 10: bins 4..17. Clockwise to window 30
  // (6 bins the other way): bins 30..11. Half a turn (window 20): the way core::wrap_angle gives.
  EXPECT_DOUBLE_EQ(sweep[4], bins_sum(4, w));
  EXPECT_DOUBLE_EQ(sweep[10], bins_sum(4, 6 + w));
  EXPECT_DOUBLE_EQ(sweep[30], bins_sum(30, 6 + w));
  const bool ccw = core::wrap_angle(e.window_yaw(20) - e.window_yaw(4)) >= 0;
  EXPECT_DOUBLE_EQ(sweep[20], ccw ? bins_sum(4, 16 + w) : bins_sum(20, 16 + w));
  for (int j = 0; j < bins; ++j) {
    EXPECT_DOUBLE_EQ(e.sweep_gain(g, e.window_yaw(from), j), sweep[static_cast<size_t>(j)]);
    EXPECT_GE(sweep[static_cast<size_t>(j)],
              e.gain_at_yaw(g, e.window_yaw(j)) - 1e-9);                 // never less than the window
    EXPECT_LE(sweep[static_cast<size_t>(j)], bins_sum(0, bins) + 1e-9);  // each bin once
  }
}

TEST(Gain, BinOfAzimuthAgreesWithAtan2) {
  GainEvaluator e(GainConfig{});
  for (int i = 0; i < 3600; ++i) {
    const double a = -core::kPi + (i + 0.37) * 2 * core::kPi / 3600;
    EXPECT_EQ(e.bin_of(a), static_cast<int>(std::floor((a + core::kPi) / e.bin_width()))) << a;
  }
  EXPECT_EQ(e.bin_of(core::kPi), e.bins() - 1);
  EXPECT_NEAR(e.window_yaw(12), 0.0, 1e-12);  // window 12..19 is centred on +x
}

// The sector test and azimuth bin of most ray steps come from tables made once for a node
// anywhere in its voxel; the voxels near a range, elevation or bin boundary are tested from the
// node's own position. Wherever the node is in its voxel, each voxel lands in the reference's bin.
TEST(Gain, AnywhereInItsVoxelTheNodeCountsWhatTheReferenceCounts) {
  map::StateGrid g = free_scene();
  // Unknown voxels scattered through the free space (none occludes): every one in range counts.
  for (int z = -22; z <= 22; ++z)
    for (int y = -22; y <= 22; ++y)
      for (int x = -22; x <= 22; ++x)
        if ((x * 7 + y * 13 + z * 5) % 4 == 0 && (x || y || z)) g.set_state({x, y, z}, VoxelState::kUnknown);
  GainEvaluator e(dense_config());
  // Near the voxel's corners and faces. Not where |x| = |y| from a voxel centre: there the
  // reference's atan2 and the evaluation's boundary vectors round each their own way.
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.0001, 0.0003, 0.0999), Eigen::Vector3d(0.0999, 0.0996, 0.0001),
        Eigen::Vector3d(0.0002, 0.0997, 0.0001), Eigen::Vector3d(0.0998, 0.0001, 0.05),
        Eigen::Vector3d(0.0123, 0.0531, 0.0655)}) {
    const NodeGain fast = e.evaluate(g, p), exact = e.evaluate_exact(g, p);
    ASSERT_GT(exact.total_voxels(), 1000);
    EXPECT_EQ(fast.bin_count, exact.bin_count) << p.transpose();
  }
}

TEST(Gain, AViewpointInsideAnObstacleSeesNothing) {
  map::StateGrid g = free_scene();
  unknown_cube(g, {15, 0, 0});
  g.set_state({0, 0, 0}, VoxelState::kOccupied);
  GainEvaluator e(dense_config());
  EXPECT_EQ(e.evaluate(g, kNode).total_voxels(), 0);
  EXPECT_EQ(e.evaluate_exact(g, kNode).total_voxels(), 0);
}

TEST(Gain, DefaultRaysSampleWhatTheReferenceCounts) {
  // A half-explored room: the planner's sensor range and ray density.
  SyntheticWorld w = SyntheticWorld::two_rooms();
  map::StateGrid g(0.1);
  w.observe(g, w.start(), 0.0, runtime::PinholeCamera{}, 2);
  GainEvaluator e(GainConfig{});
  const Eigen::Vector3d p = w.start() + Eigen::Vector3d(1.0, 0.3, 0.0);
  GainStats stats;
  const NodeGain fast = e.evaluate(g, p, &stats);
  const NodeGain exact = e.evaluate_exact(g, p);
  ASSERT_GT(exact.total_voxels(), 1000);
  EXPECT_LE(fast.total_voxels(), exact.total_voxels());
  // Rays reach every voxel near the node, a sample of the far ones (about a quarter here).
  EXPECT_GE(fast.total_voxels(), exact.total_voxels() / 6);
  EXPECT_LT(core::yaw_distance(fast.yaw, exact.yaw), 3 * e.bin_width());
  EXPECT_EQ(stats.evaluations, 1);
  EXPECT_EQ(stats.rays, 128 * 10);
  EXPECT_GT(stats.steps, stats.rays);
}

}  // namespace
}  // namespace semx::planner
