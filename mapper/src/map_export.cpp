#include "semx/mapper/map_export.hpp"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "semx/mapper/checkpoint.hpp"

namespace semx::mapper {

namespace {
constexpr int32_t kOctoOffset = 32768;  // OctoMap's tree_max_val at depth 16
}

std::unique_ptr<octomap::OcTree> to_octree(const OccupancyMap& map, ExportReport* report) {
  const OccupancyParams& p = map.params();
  auto tree = std::make_unique<octomap::OcTree>(map.resolution());
  tree->setProbHit(p.prob_hit);
  tree->setProbMiss(p.prob_miss);
  tree->setClampingThresMin(p.clamp_min);
  tree->setClampingThresMax(p.clamp_max);
  tree->setOccupancyThres(p.threshold);
  ExportReport rep;
  for (const map::VoxelKey& bk : map.grid().sorted_block_keys()) {
    const map::VoxelBlock* b = map.grid().find_block(bk);
    if (b->known == 0) continue;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b->state[i] == map::VoxelState::kUnknown) continue;
      const map::VoxelKey k = map::voxel_of(bk, i);
      if (k.x < -kOctoOffset || k.x >= kOctoOffset || k.y < -kOctoOffset || k.y >= kOctoOffset ||
          k.z < -kOctoOffset || k.z >= kOctoOffset) {
        ++rep.skipped;
        continue;
      }
      const octomap::OcTreeKey ok(static_cast<uint16_t>(k.x + kOctoOffset),
                                  static_cast<uint16_t>(k.y + kOctoOffset),
                                  static_cast<uint16_t>(k.z + kOctoOffset));
      // A held voxel (OccupancyMap::kHeld) is written as OctoMap's most certain one.
      tree->setNodeValue(ok, std::min(b->log_odds[i], map.max_log_odds()), /*lazy_eval=*/true);
      ++rep.voxels;
    }
  }
  tree->updateInnerOccupancy();
  if (report) *report = rep;
  return tree;
}

ExportReport export_octomap_bt(const OccupancyMap& map, const std::string& path) {
  ExportReport rep;
  std::unique_ptr<octomap::OcTree> tree = to_octree(map, &rep);
  if (!tree->writeBinary(path)) throw MapIoError("octomap file '" + path + "': cannot write");
  return rep;
}

ExportReport export_occupied_pcd(const map::StateGrid& grid, const std::string& path, bool binary) {
  std::vector<float> xyz;
  for (const map::VoxelKey& bk : grid.sorted_block_keys()) {
    const map::VoxelBlock* b = grid.find_block(bk);
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b->state[i] != map::VoxelState::kOccupied) continue;
      const Eigen::Vector3d c = grid.keys().center(map::voxel_of(bk, i));
      xyz.insert(xyz.end(),
                 {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())});
    }
  }
  const size_t n = xyz.size() / 3;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw MapIoError("pcd file '" + path + "': cannot write: " + std::strerror(errno));
  bool ok = std::fprintf(f,
                         "# .PCD v0.7 - occupied voxel centres exported by semx\n"
                         "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                         "WIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA %s\n",
                         n, n, binary ? "binary" : "ascii") > 0;
  if (binary) {
    // PCD binary data is the host's in-memory layout (little-endian on every semx target).
    ok = ok && std::fwrite(xyz.data(), sizeof(float), xyz.size(), f) == xyz.size();
  } else {
    for (size_t i = 0; ok && i < n; ++i) {
      ok = std::fprintf(f, "%.9g %.9g %.9g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) > 0;
    }
  }
  if (std::fclose(f) != 0 || !ok) throw MapIoError("pcd file '" + path + "': write failed");
  ExportReport rep;
  rep.voxels = static_cast<int64_t>(n);
  return rep;
}

}  // namespace semx::mapper
