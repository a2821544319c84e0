#include "semx/map/map_stats.hpp"

namespace semx::map {

MapStats compute_stats(const StateGrid& grid, int64_t seq, bool count_frontiers) {
  MapStats s;
  s.seq = seq;
  s.resolution = grid.resolution();
  s.free_voxels = grid.free_voxels();
  s.occupied_voxels = grid.occupied_voxels();
  const double v = grid.resolution() * grid.resolution() * grid.resolution();
  s.free_m3 = s.free_voxels * v;
  s.occupied_m3 = s.occupied_voxels * v;
  s.known_m3 = s.free_m3 + s.occupied_m3;
  const KeyBox& b = grid.known_bounds();
  if (!b.empty()) {
    s.bounds_min = grid.keys().corner(b.min);
    s.bounds_max = grid.keys().corner(b.max + VoxelKey{1, 1, 1});
  }
  s.blocks = static_cast<int64_t>(grid.num_blocks());
  s.memory_bytes = static_cast<int64_t>(grid.memory_bytes());
  if (count_frontiers) s.frontier_voxels = grid.count_frontiers();
  return s;
}

}  // namespace semx::map
