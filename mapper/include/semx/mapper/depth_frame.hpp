// One depth image with its camera model and pose, as the integrator reads it (a view: the pixels
// are not copied, so a node can pass its decoded message buffer straight in).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "semx/runtime/pinhole_camera.hpp"

namespace semx::mapper {

struct DepthFrame {
  int64_t utime = 0;
  runtime::PinholeCamera camera;
  // Pose of the optical frame (z forward, x right, y down) in the world.
  Eigen::Isometry3d T_world_optical = Eigen::Isometry3d::Identity();
  // Row-major z-depth in millimetres (runtime::kDepthInvalid / kDepthNoReturn reserved),
  // camera.width * camera.height values, not owned.
  const uint16_t* depth = nullptr;
  size_t depth_size = 0;

  static DepthFrame view(const runtime::PinholeCamera& camera, const Eigen::Isometry3d& T_world_optical,
                         const std::vector<uint16_t>& depth, int64_t utime = 0) {
    DepthFrame f;
    f.utime = utime;
    f.camera = camera;
    f.T_world_optical = T_world_optical;
    f.depth = depth.data();
    f.depth_size = depth.size();
    return f;
  }
};

}  // namespace semx::mapper
