// The world as it really is, for the known-map oracle only (oracle_strategy.hpp): which voxels are
// occupied and which belong to the target set T the evaluator measures coverage of (reachable free
// voxels and the occupied voxels next to them; docs/evaluation.md). The planner library does not
// know the simulator: the planner node adapts the simulator's GroundTruth to this
// (planner/node/ground_truth_map.hpp), the tests a SyntheticWorld (tests/support). No other
// planner reads it.
#pragma once

#include "semx/map/voxel_key.hpp"

namespace semx::planner {

class TruthMap {
 public:
  virtual ~TruthMap() = default;
  // Voxel edge, m; keys are the map's (voxel k is the cube [k·res, (k+1)·res)).
  virtual double resolution() const = 0;
  // Every voxel the truth describes lies in the key box [min_key, min_key + dims); the oracle
  // treats everything outside as an obstacle it cannot see through and that is not in T.
  virtual map::VoxelKey min_key() const = 0;
  virtual map::VoxelKey dims() const = 0;
  // Keys inside the box only.
  virtual bool occupied(const map::VoxelKey& k) const = 0;
  virtual bool target(const map::VoxelKey& k) const = 0;
};

}  // namespace semx::planner
