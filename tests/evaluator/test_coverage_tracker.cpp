// CoverageTracker: the incremental count equals a from-scratch count after random deltas,
// snapshots (resets) and mirrors; resolution checks; full and empty maps.
#include <gtest/gtest.h>

#include <random>
#include <unordered_set>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/coverage_tracker.hpp"
#include "semx/map/map_mirror.hpp"
#include "semx/map/map_snapshot.hpp"

namespace semx::evaluator {
namespace {

std::shared_ptr<const simulator::GroundTruth> small_gt(double res = 0.1) {
  return std::make_shared<const simulator::GroundTruth>(test::small_world(), res);
}

TEST(CoverageTracker, StartsEmptyWithTheGroundTruthsTargetSet) {
  const auto gt = small_gt();
  CoverageTracker t(gt);
  EXPECT_GT(t.target_count(), 1000);
  EXPECT_EQ(t.target_count(), static_cast<int64_t>(gt->target_count()));
  EXPECT_EQ(t.covered(), 0);
  EXPECT_EQ(t.coverage(), 0.0);
  map::StateGrid empty(0.1);
  EXPECT_EQ(CoverageTracker::count_covered(*gt, empty), 0);
}

TEST(CoverageTracker, IncrementalCountEqualsBruteForceOnRandomDeltas) {
  const auto gt = small_gt();
  CoverageTracker tracker(gt);
  map::StateGrid grid(0.1);
  std::mt19937 rng(12345);
  // Keys in the ground truth's grid and 3 voxels around it (outside T).
  const Eigen::Vector3i lo = gt->min_key() - Eigen::Vector3i::Constant(3);
  const Eigen::Vector3i hi = gt->min_key() + gt->dims() + Eigen::Vector3i::Constant(2);
  std::uniform_int_distribution<int> dx(lo.x(), hi.x()), dy(lo.y(), hi.y()), dz(lo.z(), hi.z());
  std::uniform_int_distribution<int> state(0, 9);  // mostly known states, some back to unknown
  for (int round = 0; round < 120; ++round) {
    map::MapDelta d;
    d.seq = round + 1;
    d.utime = round * 100000;
    d.resolution = 0.1;
    std::unordered_set<map::VoxelKey> used;
    const int n = 50 + static_cast<int>(rng() % 400);
    for (int i = 0; i < n; ++i) {
      const map::VoxelKey k(dx(rng), dy(rng), dz(rng));
      if (!used.insert(k).second) continue;
      const int s = state(rng);
      const auto vs =
          s == 0 ? map::VoxelState::kUnknown : (s < 7 ? map::VoxelState::kFree : map::VoxelState::kOccupied);
      d.changes.push_back({k, vs});
      grid.set_state(k, vs);
    }
    ASSERT_TRUE(tracker.apply(d));
    ASSERT_EQ(tracker.covered(), CoverageTracker::count_covered(*gt, grid)) << "after delta " << round;
    if (round % 25 == 24) {
      CoverageTracker fresh(gt);
      ASSERT_TRUE(fresh.reset(grid));
      EXPECT_EQ(fresh.covered(), tracker.covered());
    }
  }
  EXPECT_GT(tracker.covered(), 0);
  EXPECT_LT(tracker.covered(), tracker.target_count());
}

TEST(CoverageTracker, FollowsAMirrorThroughDeltasAndASnapshotAfterAGap) {
  const auto gt = small_gt();
  const auto deltas = test::sweep_deltas(*gt, 12, 0, 500000);
  map::StateGrid truth(0.1);  // the mapper's map
  map::MapMirror mirror(0.1);
  CoverageTracker tracker(gt);
  int64_t previous = 0;
  for (const auto& d : deltas) {
    for (const auto& c : d.changes) truth.set_state(c.key, c.state);
    if (d.seq == 5) continue;  // lost
    if (d.seq == 8) {
      // The client asked; the mapper answers with a snapshot of its map at seq 8.
      mirror.apply(d);  // buffered (gap)
      ASSERT_TRUE(mirror.needs_snapshot());
      ASSERT_EQ(mirror.apply(map::encode_snapshot(truth, 8, d.utime)),
                map::MapMirror::SnapshotResult::kApplied);
      ASSERT_TRUE(tracker.reset(mirror.grid()));
    } else if (mirror.apply(d) == map::MapMirror::DeltaResult::kApplied) {
      ASSERT_TRUE(tracker.apply(d));
    }
    if (mirror.needs_snapshot()) continue;
    EXPECT_EQ(tracker.covered(), CoverageTracker::count_covered(*gt, mirror.grid())) << "seq " << d.seq;
    EXPECT_GE(tracker.covered(), previous);
    previous = tracker.covered();
  }
  // The whole sweep reveals every target voxel.
  EXPECT_EQ(tracker.covered(), tracker.target_count());
  EXPECT_DOUBLE_EQ(tracker.coverage(), 1.0);
}

TEST(CoverageTracker, RefusesAnotherResolution) {
  const auto gt = small_gt();
  CoverageTracker tracker(gt);
  map::MapDelta d;
  d.resolution = 0.2;
  d.changes.push_back({map::VoxelKey(5, 5, 5), map::VoxelState::kFree});
  EXPECT_FALSE(tracker.apply(d));
  EXPECT_EQ(tracker.covered(), 0);
  map::StateGrid g(0.2);
  g.set_state({5, 5, 5}, map::VoxelState::kFree);
  EXPECT_FALSE(tracker.reset(g));
  EXPECT_TRUE(tracker.matches(0.1 + 1e-12));
}

TEST(CoverageTracker, CountsOnlyTargetVoxels) {
  const auto gt = small_gt();
  CoverageTracker tracker(gt);
  // The start's voxel is reachable free; a voxel inside the floor slab's interior is not in T.
  const Eigen::Vector3i start = gt->key_of({1.0, 1.2, 0.8});
  ASSERT_TRUE(gt->in_target(start));
  tracker.set({start.x(), start.y(), start.z()}, map::VoxelState::kOccupied);
  EXPECT_EQ(tracker.covered(), 1);
  tracker.set({start.x(), start.y(), start.z()}, map::VoxelState::kFree);  // still known
  EXPECT_EQ(tracker.covered(), 1);
  tracker.set({start.x(), start.y(), start.z()}, map::VoxelState::kUnknown);
  EXPECT_EQ(tracker.covered(), 0);
  tracker.set({1000, 1000, 1000}, map::VoxelState::kFree);  // far outside the world
  const Eigen::Vector3i wall_far_side = gt->key_of({1.5, -0.15, 0.8});
  ASSERT_FALSE(gt->in_target(wall_far_side));
  tracker.set({wall_far_side.x(), wall_far_side.y(), wall_far_side.z()}, map::VoxelState::kOccupied);
  EXPECT_EQ(tracker.covered(), 0);
}

TEST(CoverageTracker, ObjectCoverageCountsTheFurnituresSurfaceOnly) {
  const auto gt = small_gt();
  CoverageTracker tracker(gt);
  ASSERT_EQ(gt->objects().size(), 1u);  // the table
  const simulator::ObjectInfo& table = gt->objects().front();
  const Eigen::Vector3d lo = table.center - 0.5 * table.extent, hi = table.center + 0.5 * table.extent;
  // Brute force: occupied target voxels whose cube overlaps the table's box with some volume.
  int64_t expected = 0;
  std::vector<map::VoxelKey> table_voxels;
  const Eigen::Vector3i k0 = gt->min_key(), d = gt->dims();
  for (int z = 0; z < d.z(); ++z)
    for (int y = 0; y < d.y(); ++y)
      for (int x = 0; x < d.x(); ++x) {
        const Eigen::Vector3i k = k0 + Eigen::Vector3i(x, y, z);
        const Eigen::Vector3d a = k.cast<double>() * 0.1, b = a + Eigen::Vector3d::Constant(0.1);
        const bool overlaps = ((a.array() < hi.array() - 1e-9) && (b.array() > lo.array() + 1e-9)).all();
        if (!overlaps || !gt->in_target(k) || gt->cell(k) != simulator::GroundTruth::kOccupied) continue;
        ++expected;
        table_voxels.emplace_back(k.x(), k.y(), k.z());
      }
  ASSERT_GT(expected, 50);  // the table's top and sides
  EXPECT_EQ(tracker.object_target_count(), expected);
  EXPECT_EQ(tracker.object_coverage(), 0.0);
  // A wall voxel in T counts for coverage, not for the objects; a table voxel for both.
  const Eigen::Vector3i wall = gt->key_of({1.5, -0.05, 0.8});
  ASSERT_TRUE(gt->in_target(wall));
  tracker.set({wall.x(), wall.y(), wall.z()}, map::VoxelState::kOccupied);
  EXPECT_EQ(tracker.covered(), 1);
  EXPECT_EQ(tracker.object_covered(), 0);
  for (const auto& k : table_voxels) tracker.set(k, map::VoxelState::kOccupied);
  EXPECT_EQ(tracker.object_covered(), expected);
  EXPECT_DOUBLE_EQ(tracker.object_coverage(), 1.0);
  tracker.set(table_voxels.front(), map::VoxelState::kUnknown);
  EXPECT_EQ(tracker.object_covered(), expected - 1);
  tracker.clear();
  EXPECT_EQ(tracker.object_covered(), 0);
}

}  // namespace
}  // namespace semx::evaluator
