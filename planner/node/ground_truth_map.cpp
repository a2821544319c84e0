#include "ground_truth_map.hpp"

namespace semx::planner {

GroundTruthMap::GroundTruthMap(const simulator::World& world, double resolution)
    : name_(world.name), gt_(world, resolution) {}

std::unique_ptr<GroundTruthMap> GroundTruthMap::load(const std::string& world, double resolution) {
  return std::make_unique<GroundTruthMap>(simulator::load_world(simulator::shipped_world_path(world)), resolution);
}

map::VoxelKey GroundTruthMap::min_key() const {
  const Eigen::Vector3i& k = gt_.min_key();
  return {k.x(), k.y(), k.z()};
}

map::VoxelKey GroundTruthMap::dims() const {
  const Eigen::Vector3i& d = gt_.dims();
  return {d.x(), d.y(), d.z()};
}

bool GroundTruthMap::occupied(const map::VoxelKey& k) const {
  return gt_.cell(Eigen::Vector3i(k.x, k.y, k.z)) == simulator::GroundTruth::kOccupied;
}

bool GroundTruthMap::target(const map::VoxelKey& k) const { return gt_.in_target(Eigen::Vector3i(k.x, k.y, k.z)); }

}  // namespace semx::planner
