// Coverage of a world's ground truth by the mapper's map (DESIGN.md §5), kept incrementally.
//
//   T           = the ground truth's target set at the map resolution (GroundTruth::in_target):
//                 reachable free voxels and the occupied voxels next to them;
//   coverage(t) = |{v in T : the map's state of v is not unknown}| / |T|.
//
// The tracker keeps one "known" flag per ground-truth cell and the number of target voxels
// whose flag is set. A MAP_UPDATE delta carries the new state of every voxel it changes, so
// applying it only touches those voxels; a MAP_SNAPSHOT (which may change anything) is handled
// by a recount from the map (reset). count_covered() is the same number computed from scratch,
// for tests and checks: after any sequence of deltas and resets both agree.
//
// Object coverage, the same count over the objects' surfaces: the occupied target voxels whose
// cube overlaps an object's box (GroundTruth::objects(), the box around its solids), i.e. the
// furniture a semantic planner is meant to look at, without walls, floor and ceiling.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/simulator/ground_truth.hpp"

namespace semx::evaluator {

class CoverageTracker {
 public:
  // `gt` fixes the resolution: deltas and grids must have the same voxel size.
  explicit CoverageTracker(std::shared_ptr<const simulator::GroundTruth> gt);

  const simulator::GroundTruth& ground_truth() const { return *gt_; }
  double resolution() const { return gt_->resolution(); }
  // True when `resolution` is this tracker's (to 1e-9 relative).
  bool matches(double resolution) const;

  int64_t target_count() const { return static_cast<int64_t>(gt_->target_count()); }
  int64_t covered() const { return covered_; }
  // covered() / target_count() in [0, 1]; 0 for an empty target set.
  double coverage() const;
  // The same over the objects' surface voxels.
  int64_t object_target_count() const { return object_target_; }
  int64_t object_covered() const { return object_covered_; }
  double object_coverage() const;

  // Records the new state of one voxel (voxels outside T change nothing).
  void set(const map::VoxelKey& key, map::VoxelState state);
  // Applies every change of a delta. Returns false (and changes nothing) when the delta's
  // resolution is not the tracker's.
  bool apply(const map::MapDelta& delta);
  // Forgets everything and recounts from `grid` (after a snapshot replaced the map). Returns
  // false (and leaves the tracker empty) when the grid's resolution is not the tracker's.
  bool reset(const map::StateGrid& grid);
  // Forgets everything: coverage 0.
  void clear();

  bool known(const map::VoxelKey& key) const;

  // From scratch: the target voxels whose state in `grid` is not unknown (grid at gt's resolution).
  static int64_t count_covered(const simulator::GroundTruth& gt, const map::StateGrid& grid);

 private:
  std::shared_ptr<const simulator::GroundTruth> gt_;
  std::vector<uint8_t> known_;   // per ground-truth cell (GroundTruth::index), target cells only
  std::vector<uint8_t> object_;  // per cell: an object's surface voxel in T
  int64_t covered_ = 0;
  int64_t object_target_ = 0, object_covered_ = 0;
};

}  // namespace semx::evaluator
