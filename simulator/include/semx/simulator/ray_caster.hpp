// Reference renderer: one analytic ray per pixel against every solid (slab test for yawed
// boxes, quadratic + caps for cylinders). Slow and simple on purpose: tests and the perf tool
// hold the rasteriser against it.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <utility>
#include <vector>

#include "semx/runtime/pinhole_camera.hpp"
#include "semx/simulator/camera_frame.hpp"
#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct RayHit {
  double t = 0;  // ray parameter: hit point = origin + t * direction
  int solid = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // outward, world
};

// First entry of the ray into the solid with t in [t_min, t_max]. A ray starting inside a solid
// does not hit it (the rasteriser culls back faces, so it sees through such a solid too).
std::optional<RayHit> intersect(const Solid& solid, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                double t_min, double t_max);

class RayCaster {
 public:
  explicit RayCaster(World world);

  std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                             double t_max) const;

  // Same outputs and conventions as Rasterizer::render; RGB uses the same flat shading.
  void render(const runtime::PinholeCamera& camera, const Eigen::Isometry3d& pose, unsigned channels,
              CameraFrame& out, double rgb_far = 0.0) const;

 private:
  World world_;
  std::vector<double> cos_, sin_;  // of each solid's yaw
};

}  // namespace semx::simulator
