// Summary figures of a map (MAP_STATS).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semx/map/state_grid.hpp"

namespace semx::map {

struct MapStats {
  int64_t seq = 0;
  double resolution = 0.0;
  int64_t free_voxels = 0;
  int64_t occupied_voxels = 0;
  int64_t frontier_voxels = -1;  // -1 when not counted (the count is O(map))
  double known_m3 = 0.0;
  double free_m3 = 0.0;
  double occupied_m3 = 0.0;
  // Bounding box of known space, metres (voxel faces); zero when nothing is known.
  Eigen::Vector3d bounds_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bounds_max = Eigen::Vector3d::Zero();
  int64_t blocks = 0;
  int64_t memory_bytes = 0;
  // Filled by Mapper.
  int64_t frames_integrated = 0;
  int64_t frames_rejected = 0;
  double integrate_ms = 0.0;  // last frame's integration time (wall clock, for monitoring only)
};

MapStats compute_stats(const StateGrid& grid, int64_t seq, bool count_frontiers = true);

}  // namespace semx::map
