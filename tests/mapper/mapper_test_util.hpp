// Helpers shared by the mapper tests.
#pragma once

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "semx/fixtures/synthetic_room.hpp"
#include "semx/map/map_mirror.hpp"
#include "semx/mapper/mapper.hpp"

namespace semx::mapper::test {

// A camera of w x h pixels whose pixel (0, 0) looks exactly along the optical axis.
inline runtime::PinholeCamera axis_camera(int w = 1, int h = 1, double f = 1.0) {
  runtime::PinholeCamera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = f;
  c.cx = 0.0;
  c.cy = 0.0;
  c.min_range = 0.5;
  c.max_range = 5.0;
  return c;
}

// Optical axis along world +x, camera at p.
inline Eigen::Isometry3d looking_along_x(const Eigen::Vector3d& p) { return camera_pose(p, 0.0, 0.0); }

inline MapperConfig config_with_mode(IntegrationParams::Mode mode) {
  MapperConfig c;
  c.integration.mode = mode;
  return c;
}

// Frames of the furnished room from a loop of poses near its centre (those of semx-perf-mapper).
struct RoomFrame {
  Eigen::Isometry3d pose;
  std::vector<uint16_t> depth;
};
inline std::vector<RoomFrame> room_frames(int n, const runtime::PinholeCamera& cam, int of = 24) {
  const SyntheticRoom room = SyntheticRoom::furnished();
  std::vector<RoomFrame> frames;
  for (int k = 0; k < n; ++k) {
    RoomFrame f{room_loop_pose(k, of), {}};
    f.depth = room.render(cam, f.pose);
    frames.push_back(std::move(f));
  }
  return frames;
}

// A smaller camera keeps the tests fast while still covering the room.
inline runtime::PinholeCamera small_camera() {
  runtime::PinholeCamera c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 80.0;
  c.cx = 80.0;
  c.cy = 60.0;
  return c;
}

// The same frame through OctoMap's insertPointCloud (the reference for agreement).
inline void octomap_insert(octomap::OcTree& tree, const runtime::PinholeCamera& cam, const RoomFrame& f) {
  octomap::Pointcloud cloud;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const uint16_t d = f.depth[static_cast<size_t>(v) * cam.width + u];
      if (d == runtime::kDepthInvalid || d == runtime::kDepthNoReturn) continue;
      const double z = d * 0.001;
      if (z < cam.min_range || z > cam.max_range) continue;
      const Eigen::Vector3d p = f.pose * cam.unproject(u, v, z);
      cloud.push_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
  }
  const Eigen::Vector3d o = f.pose.translation();
  tree.insertPointCloud(cloud, octomap::point3d(o.x(), o.y(), o.z()), -1.0, false, false);
}

// Fraction of voxels known to either map on which both agree.
inline double agreement(const map::StateGrid& grid, octomap::OcTree& tree) {
  constexpr int32_t kOff = 32768;
  int64_t agree = 0, total = 0;
  grid.for_each_block([&](const map::VoxelKey& bk, const map::VoxelBlock& b) {
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b.state[i] == map::VoxelState::kUnknown) continue;
      const map::VoxelKey k = map::voxel_of(bk, i);
      const octomap::OcTreeNode* n = tree.search(octomap::OcTreeKey(k.x + kOff, k.y + kOff, k.z + kOff));
      ++total;
      if (n && (tree.isNodeOccupied(n) ? map::VoxelState::kOccupied : map::VoxelState::kFree) == b.state[i])
        ++agree;
    }
  });
  tree.expand();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey k = it.getKey();
    if (grid.state(map::VoxelKey{k[0] - kOff, k[1] - kOff, k[2] - kOff}) == map::VoxelState::kUnknown)
      ++total;
  }
  return total ? static_cast<double>(agree) / total : 1.0;
}

// Per process: two test runs at once (two checkouts, or CI beside a developer) must not share a file.
inline std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "semx_mapper_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace semx::mapper::test
