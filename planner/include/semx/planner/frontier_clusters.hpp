// FUEL's incremental frontier structure (Zhou et al. 2021, §IV-A; frontier_finder.cpp): the
// frontier voxels (FrontierTracker's: unknown, a free face neighbour) grouped in connected
// clusters (26-connectivity), kept across map updates.
//
// update() is given the voxels whose frontier status may have changed (a changed voxel and its
// face neighbours) and does what FUEL's searchFrontiers does around the updated region: a cluster
// that lost any of its voxels is removed, and new clusters are grown (region growing) from every
// eligible voxel no cluster holds, stopping at voxels of clusters that did not change. A grown
// group with fewer than min_voxels voxels is not a cluster (FUEL's cluster_min); one whose voxels
// reach farther than split_radius horizontally from its mean is cut in two through the mean,
// across its first principal axis in the horizontal plane, and each half again while it is too
// large (FUEL's splitHorizontally). Clusters that did not change keep their id and everything
// the caller attached to it (viewpoints, travel costs), so the work per update is proportional to
// the change.
//
// Which voxels are eligible is the caller's (FUEL's planner: frontier voxels not known to be
// unobservable). Clusters and their voxels are ordered (ids ascending, voxels by key), so the
// same updates give the same clusters.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <unordered_map>
#include <vector>

#include "semx/map/voxel_key.hpp"

namespace semx::planner {

class FrontierClusters {
 public:
  struct Cluster {
    int64_t id = -1;
    std::vector<map::VoxelKey> voxels;  // ascending key order
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // of the voxel centres, m
    map::KeyBox box;
  };
  struct Changes {
    std::vector<int64_t> removed;  // ids that no longer exist
    std::vector<int64_t> added;    // new ids, ascending
  };
  using Eligible = std::function<bool(const map::VoxelKey&)>;

  FrontierClusters(double resolution, int min_voxels, double split_radius);

  // Forgets every cluster (their ids are not reused).
  void clear();
  // Re-examines `dirty` (voxels that may have become or stopped being eligible).
  Changes update(const std::vector<map::VoxelKey>& dirty, const Eligible& eligible);
  // Builds every cluster from scratch out of `voxels` (all eligible ones, any order).
  Changes rebuild(std::vector<map::VoxelKey> voxels, const Eligible& eligible);

  const std::map<int64_t, Cluster>& clusters() const { return clusters_; }
  const Cluster* find(int64_t id) const;
  // The cluster holding voxel k, or -1.
  int64_t owner(const map::VoxelKey& k) const;
  double resolution() const { return resolution_; }

  // Splits `voxels` as update() does (exposed for tests): groups no larger than split_radius.
  std::vector<std::vector<map::VoxelKey>> split(std::vector<map::VoxelKey> voxels) const;

 private:
  void remove(int64_t id, std::vector<map::VoxelKey>& freed, Changes& out);
  void grow(std::vector<map::VoxelKey> seeds, const Eligible& eligible, Changes& out);
  void add(std::vector<map::VoxelKey> voxels, Changes& out);
  Eigen::Vector3d centre(const map::VoxelKey& k) const;

  double resolution_;
  int min_voxels_;
  double split_radius_;
  int64_t next_id_ = 0;
  std::map<int64_t, Cluster> clusters_;
  std::unordered_map<map::VoxelKey, int64_t> owner_;
};

}  // namespace semx::planner
