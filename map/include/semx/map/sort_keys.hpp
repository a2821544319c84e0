// Voxel keys in VoxelKey's order ((z, y, x)) without repeats: what std::sort and std::unique
// give, on 64-bit packings of the keys when they span less than 2^21 voxels on every axis (any
// map of this system: 210 km at 0.1 m), and by VoxelKey's comparison otherwise. FUEL's frontier
// bookkeeping sorts ~10^5 keys a cycle; three-way comparisons of 12-byte keys were a tenth of its
// planning time in a 600 m² world.
#pragma once

#include <vector>

#include "semx/map/voxel_key.hpp"

namespace semx::map {

void sort_unique(std::vector<VoxelKey>& keys);

}  // namespace semx::map
