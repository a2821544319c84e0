// The one pinhole camera convention of semx, shared by the simulator (which renders), the
// mapper (which ray-casts) and semantics (which back-projects), so the three cannot disagree.
//
// Frames: the camera's optical frame has z forward, x right, y down. A sensor pose is the pose of
// that optical frame in the world (world: z up). Pixel (u, v) is column u, row v; its centre
// projects from the optical-frame point (x, y, z) as u = fx x/z + cx, v = fy y/z + cy.
// Depth images hold z (distance along the optical axis), not the ray length.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

namespace semx::runtime {

// Depth pixels are 16-bit millimetres with two reserved values.
constexpr uint16_t kDepthInvalid = 0;        // no measurement: ignore the pixel
constexpr uint16_t kDepthNoReturn = 0xFFFF;  // nothing within max range: free up to max range
constexpr uint16_t kDepthMaxEncodable = 0xFFFE;

struct PinholeCamera {
  int width = 640;
  int height = 480;
  double fx = 320.0;  // 90 deg horizontal FOV at 640 px (DESIGN.md §5)
  double fy = 320.0;
  double cx = 320.0;
  double cy = 240.0;
  double min_range = 0.5;  // metres, along the optical axis
  double max_range = 5.0;

  // Direction of pixel (u, v) in the optical frame, with z = 1 (so depth * ray is the point).
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }
  // Optical-frame point of pixel (u, v) at depth z.
  Eigen::Vector3d unproject(double u, double v, double z) const { return ray(u, v) * z; }
  // Pixel of an optical-frame point; false when behind the camera.
  bool project(const Eigen::Vector3d& p, double& u, double& v) const {
    if (p.z() <= 1e-9) return false;
    u = fx * p.x() / p.z() + cx;
    v = fy * p.y() / p.z() + cy;
    return true;
  }
  bool in_image(double u, double v) const { return u >= 0 && v >= 0 && u < width && v < height; }
  double horizontal_fov() const { return 2.0 * std::atan2(0.5 * width, fx); }
  double vertical_fov() const { return 2.0 * std::atan2(0.5 * height, fy); }
};

// Orientation R_body_optical of an optical frame that looks along the body's x axis, for a
// body frame x forward, y left, z up: optical z = body x, optical x = -body y,
// optical y = -body z. A camera's world pose is then R_world_body * R_body_optical.
inline Eigen::Matrix3d optical_in_body() {
  Eigen::Matrix3d r;
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

}  // namespace semx::runtime
