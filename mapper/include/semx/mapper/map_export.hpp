// Interop with other tools: OctoMap (.bt, opens in octovis) and PCD (opens in pcl_viewer).
#pragma once

#include <memory>
#include <string>

#include "semx/mapper/occupancy_map.hpp"

namespace octomap {
class OcTree;
}

namespace semx::mapper {

struct ExportReport {
  int64_t voxels = 0;   // written
  int64_t skipped = 0;  // outside the target format's range (OctoMap: +-32768 voxels per axis)
};

// An OctoMap tree with the same parameters and every known voxel's log-odds (same voxel grid:
// OctoMap key = semx key + 32768).
std::unique_ptr<octomap::OcTree> to_octree(const OccupancyMap& map, ExportReport* report = nullptr);
// OctoMap's binary format (free/occupied only, as every .bt). Throws MapIoError naming the file.
ExportReport export_octomap_bt(const OccupancyMap& map, const std::string& path);
// Centres of the occupied voxels as a PCD v0.7 point cloud (fields x y z, float32), binary or
// ASCII. Throws MapIoError naming the file.
ExportReport export_occupied_pcd(const map::StateGrid& grid, const std::string& path, bool binary = true);

}  // namespace semx::mapper
