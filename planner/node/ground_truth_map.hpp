// The simulator's ground truth (simulator/ground_truth.hpp) as the known-map oracle's TruthMap:
// the same occupied voxels and the same target set T the evaluator measures coverage of, at the
// same resolution. Only `semx-planner --planner oracle` builds one (--world FILE).
#pragma once

#include <memory>
#include <string>

#include "semx/planner/truth_map.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"

namespace semx::planner {

class GroundTruthMap : public TruthMap {
 public:
  GroundTruthMap(const simulator::World& world, double resolution);
  // A shipped world's name (env1, env2, env3) or a world file; throws simulator::WorldError.
  static std::unique_ptr<GroundTruthMap> load(const std::string& world, double resolution);

  double resolution() const override { return gt_.resolution(); }
  map::VoxelKey min_key() const override;
  map::VoxelKey dims() const override;
  bool occupied(const map::VoxelKey& k) const override;
  bool target(const map::VoxelKey& k) const override;

  const simulator::GroundTruth& ground_truth() const { return gt_; }
  const std::string& world_name() const { return name_; }

 private:
  std::string name_;
  simulator::GroundTruth gt_;
};

}  // namespace semx::planner
