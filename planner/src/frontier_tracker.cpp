#include "semx/planner/frontier_tracker.hpp"

#include <cmath>

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

FrontierTracker::FrontierTracker(double cluster_size) : cluster_size_(cluster_size) {}

void FrontierTracker::clear() {
  frontier_.clear();
  bits_.clear();
  cells_.clear();
}

VoxelKey FrontierTracker::cell_of(const VoxelKey& k) const {
  const double s = cluster_size_ / resolution_;
  return {static_cast<int32_t>(std::floor((k.x + 0.5) / s)),
          static_cast<int32_t>(std::floor((k.y + 0.5) / s)),
          static_cast<int32_t>(std::floor((k.z + 0.5) / s))};
}

void FrontierTracker::set(const VoxelKey& k, bool frontier) {
  if (frontier) {
    if (!frontier_.insert(k).second) return;
    bits_.insert(k);
    Cell& c = cells_[cell_of(k)];
    ++c.voxels;
    c.sx += k.x;
    c.sy += k.y;
    c.sz += k.z;
  } else {
    if (frontier_.erase(k) == 0) return;
    bits_.erase(k);
    auto it = cells_.find(cell_of(k));
    if (it == cells_.end()) return;
    Cell& c = it->second;
    --c.voxels;
    c.sx -= k.x;
    c.sy -= k.y;
    c.sz -= k.z;
    if (c.voxels <= 0) cells_.erase(it);
  }
}

void FrontierTracker::recheck(map::StateGrid::Reader& r, const VoxelKey& k) {
  bool frontier = false;
  if (r.state(k) == VoxelState::kUnknown) {
    for (const VoxelKey& d : map::kFaceNeighbours) {
      if (r.state(k + d) == VoxelState::kFree) {
        frontier = true;
        break;
      }
    }
  }
  set(k, frontier);
}

void FrontierTracker::update(const map::StateGrid& grid, const std::vector<map::VoxelChange>& changes) {
  if (resolution_ != grid.resolution()) {
    reset(grid);
    return;
  }
  map::StateGrid::Reader r = grid.reader();
  for (const map::VoxelChange& c : changes) {
    recheck(r, c.key);
    for (const VoxelKey& d : map::kFaceNeighbours) recheck(r, c.key + d);
  }
}

void FrontierTracker::reset(const map::StateGrid& grid) {
  clear();
  resolution_ = grid.resolution();
  map::StateGrid::Reader r = grid.reader();
  std::vector<VoxelKey> candidates;
  grid.for_each_block([&](const VoxelKey& block, const map::VoxelBlock& b) {
    if (b.known == 0) return;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b.state[static_cast<size_t>(i)] != VoxelState::kFree) continue;
      const VoxelKey k = map::voxel_of(block, i);
      for (const VoxelKey& d : map::kFaceNeighbours) {
        if (r.state(k + d) == VoxelState::kUnknown) candidates.push_back(k + d);
      }
    }
  });
  for (const VoxelKey& k : candidates) set(k, true);
}

std::vector<FrontierTracker::Cluster> FrontierTracker::clusters(int64_t min_voxels) const {
  std::vector<Cluster> out;
  for (const auto& [cell, c] : cells_) {
    if (c.voxels < min_voxels) continue;
    Cluster cl;
    cl.cell = cell;
    cl.voxels = c.voxels;
    const double n = static_cast<double>(c.voxels);
    cl.centre = Eigen::Vector3d((c.sx / n + 0.5) * resolution_, (c.sy / n + 0.5) * resolution_,
                                (c.sz / n + 0.5) * resolution_);
    out.push_back(cl);
  }
  return out;
}

}  // namespace semx::planner
