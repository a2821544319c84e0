// The frontier voxels of the map (unknown with a free face neighbour), kept up to date from the
// map's changes, and grouped in cubic cells ("clusters") that the sampler draws candidates around
// and the main loop uses to tell whether any frontier is left.
//
// update() re-examines each changed voxel and its six neighbours (the only voxels whose frontier
// status a change can flip), so its cost is proportional to the change, not to the map. reset()
// scans the whole map (after a snapshot replaced it).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <unordered_set>
#include <vector>

#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/voxel_set.hpp"

namespace semx::planner {

class FrontierTracker {
 public:
  explicit FrontierTracker(double cluster_size = 1.0);

  void reset(const map::StateGrid& grid);
  void update(const map::StateGrid& grid, const std::vector<map::VoxelChange>& changes);
  void clear();

  size_t size() const { return frontier_.size(); }
  bool contains(const map::VoxelKey& k) const { return bits_.contains(k); }
  // Every frontier voxel (unordered: callers that decide on them sort first).
  const std::unordered_set<map::VoxelKey>& voxels() const { return frontier_; }
  // The same as block bit masks, for callers that look up many voxels near each other.
  const VoxelSet& bits() const { return bits_; }

  struct Cluster {
    map::VoxelKey cell;      // cell coordinates (floor(voxel centre / cluster_size))
    Eigen::Vector3d centre;  // mean of its frontier voxels' centres, m
    int64_t voxels = 0;
  };
  // Cells with at least min_voxels frontier voxels, in ascending cell order.
  std::vector<Cluster> clusters(int64_t min_voxels) const;

 private:
  struct Cell {
    int64_t voxels = 0;
    int64_t sx = 0, sy = 0, sz = 0;  // sums of voxel keys
  };
  map::VoxelKey cell_of(const map::VoxelKey& k) const;
  void set(const map::VoxelKey& k, bool frontier);
  void recheck(map::StateGrid::Reader& r, const map::VoxelKey& k);

  double cluster_size_;
  double resolution_ = 0.0;
  std::unordered_set<map::VoxelKey> frontier_;
  VoxelSet bits_;  // frontier_ again, one bit per voxel
  std::map<map::VoxelKey, Cell> cells_;
};

}  // namespace semx::planner
