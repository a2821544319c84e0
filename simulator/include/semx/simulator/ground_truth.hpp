// Ground truth for evaluation (DESIGN.md §5): a world voxelised at the map resolution.
// Voxel key (i, j, k) is the cube [i·res, (i+1)·res) x [j·res, ...) x [k·res, ...) in world
// coordinates, the same keying the mapper must use for coverage to be comparable.
//   occupied        = voxels whose cube overlaps a solid with positive volume;
//   reachable free  = free voxels 6-connected to the start's voxel through free voxels whose
//                     centres lie inside the world bounds;
//   target set T    = reachable free ∪ occupied voxels 6-adjacent to a reachable free voxel.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct ObjectInfo {
  SemanticClass cls = SemanticClass::kNone;
  uint16_t instance = 0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // of the axis-aligned box around its solids
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();  // full size of that box
  int solids = 0;
};

// Objects (non-structural instances) of a world, by instance id.
std::vector<ObjectInfo> list_objects(const World& world);

class GroundTruth {
 public:
  enum Cell : uint8_t { kFree = 0, kOccupied = 1, kReachable = 2 };

  GroundTruth(const World& world, double resolution = 0.1);

  double resolution() const { return res_; }
  const Eigen::Vector3i& min_key() const { return min_key_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  Eigen::Vector3i key_of(const Eigen::Vector3d& p) const;
  Eigen::Vector3d center_of(const Eigen::Vector3i& key) const;
  bool in_grid(const Eigen::Vector3i& key) const;
  // Cell of a key (kFree outside the grid).
  Cell cell(const Eigen::Vector3i& key) const;
  bool in_target(const Eigen::Vector3i& key) const;
  // Linear index inside the grid (x fastest); keys must be in_grid.
  size_t index(const Eigen::Vector3i& key) const;
  const std::vector<uint8_t>& cells() const { return cells_; }
  const std::vector<uint8_t>& target() const { return target_; }

  size_t occupied_count() const { return occupied_; }
  size_t reachable_free_count() const { return reachable_; }
  size_t occupied_in_target_count() const { return occupied_target_; }
  size_t target_count() const { return reachable_ + occupied_target_; }
  // Floor-plan area of the reachable space: columns holding a reachable voxel, times res².
  double reachable_area() const { return area_; }
  const std::vector<ObjectInfo>& objects() const { return objects_; }

 private:
  double res_;
  Eigen::Vector3i min_key_, dims_;
  std::vector<uint8_t> cells_;
  std::vector<uint8_t> target_;
  size_t occupied_ = 0, reachable_ = 0, occupied_target_ = 0;
  double area_ = 0;
  std::vector<ObjectInfo> objects_;
};

// Where the vehicle's body (axis-aligned, any yaw fits in it) can go from the start without
// touching an occupied voxel: voxel centres flooded in configuration space. Used to check that
// a world's rooms are reachable by the vehicle, not just by a voxel of air.
class VehicleReachability {
 public:
  // `gt` must outlive this object.
  VehicleReachability(const GroundTruth& gt, const Eigen::Vector3d& start,
                      const Eigen::Vector3d& body_size = kVehicleSize);
  bool reachable(const Eigen::Vector3d& p) const;
  size_t count() const { return count_; }

 private:
  const GroundTruth& gt_;
  std::vector<uint8_t> reach_;
  size_t count_ = 0;
};

}  // namespace semx::simulator
