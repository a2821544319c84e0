// A small world and a "mapping" of it built from its own ground truth, for the evaluator tests.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "semx/map/map_delta.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"

namespace semx::evaluator::test {

// A 3 x 2.5 x 1.6 m room with a table: a ground truth of a few thousand voxels at 0.1 m.
inline const char* kSmallWorldYaml = R"(name: small
bounds: {min: [-0.2, -0.2, -0.1], max: [3.2, 2.7, 1.7]}
start: {position: [1.0, 1.2, 0.8], yaw_deg: 0}
solids:
  - {type: box, class: floor, center: [1.5, 1.25, -0.05], size: [3.4, 2.9, 0.1]}
  - {type: box, class: ceiling, center: [1.5, 1.25, 1.65], size: [3.4, 2.9, 0.1]}
  - {type: box, class: wall, center: [1.5, -0.1, 0.8], size: [3.4, 0.2, 1.6]}
  - {type: box, class: wall, center: [1.5, 2.6, 0.8], size: [3.4, 0.2, 1.6]}
  - {type: box, class: wall, center: [-0.1, 1.25, 0.8], size: [0.2, 2.5, 1.6]}
  - {type: box, class: wall, center: [3.1, 1.25, 0.8], size: [0.2, 2.5, 1.6]}
  - {type: box, class: table, center: [2.3, 1.7, 0.3], size: [0.6, 0.5, 0.6]}
)";

inline simulator::World small_world() { return simulator::parse_world(kSmallWorldYaml, "small.yaml"); }

inline std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "semx_eval_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(d);
  return d;
}

// Writes the small world to a file (for the executables and the log evaluator).
inline std::string small_world_file(const std::string& dir) {
  std::filesystem::create_directories(dir);
  const std::string p = dir + "/small.yaml";
  std::ofstream(p) << kSmallWorldYaml;
  return p;
}

// The map a perfect mapper would build, revealed in `n` deltas sweeping along x: every target
// voxel with its ground-truth state, plus a few voxels outside the target set (every fourth
// delta is empty). Delta k (seq k+1) is stamped t0 + k * dt.
inline std::vector<map::MapDelta> sweep_deltas(const simulator::GroundTruth& gt, int n, int64_t t0_us,
                                               int64_t dt_us) {
  std::vector<map::VoxelKey> keys;
  const Eigen::Vector3i lo = gt.min_key(), d = gt.dims();
  for (int x = 0; x < d.x(); ++x) {
    for (int y = 0; y < d.y(); ++y) {
      for (int z = 0; z < d.z(); ++z) {
        const Eigen::Vector3i k(lo.x() + x, lo.y() + y, lo.z() + z);
        // All target voxels and every 7th other voxel (walls' far side, outside the bounds...).
        if (gt.in_target(k) || (x + 3 * y + 5 * z) % 7 == 0) keys.emplace_back(k.x(), k.y(), k.z());
      }
    }
  }
  std::vector<map::MapDelta> out(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    out[i].seq = i + 1;
    out[i].utime = t0_us + i * dt_us;
    out[i].resolution = gt.resolution();
  }
  // Every fourth delta is empty, as the mapper's are when a frame changes nothing (and an
  // empty array after a full one is where a reused decoder keeps stale content).
  std::vector<size_t> full;
  for (int i = 0; i < n; ++i) {
    if (i % 4 != 3 || n < 4) full.push_back(static_cast<size_t>(i));
  }
  for (size_t j = 0; j < keys.size(); ++j) {
    const size_t i = full[j * full.size() / keys.size()];
    const Eigen::Vector3i k(keys[j].x, keys[j].y, keys[j].z);
    out[i].changes.push_back({keys[j], gt.cell(k) == simulator::GroundTruth::kOccupied
                                           ? map::VoxelState::kOccupied
                                           : map::VoxelState::kFree});
  }
  return out;
}

}  // namespace semx::evaluator::test
