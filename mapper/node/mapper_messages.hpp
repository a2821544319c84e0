// The mapper's own inputs as messages: CAMERA_DEPTH decoded into a frame the integrator can
// view, and the ODOMETRY check (the map messages it sends are map/node/map_messages.hpp's).
#pragma once

#include <semx/depth_image_t.hpp>
#include <semx/odometry_t.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/mapper/depth_frame.hpp"
#include "semx/runtime/camera_info.hpp"

namespace semx::mapper {

// ---- CAMERA_DEPTH (depth_image_t) ----

// Largest depth image accepted: runtime::kMaxCameraPixels (2^24 pixels, 32 MiB of raw depth),
// checked before anything is decompressed, so a small zlib bomb cannot make the mapper allocate
// gigabytes.
inline constexpr int64_t kMaxDepthPixels = runtime::kMaxCameraPixels;

// A depth message decoded into pixels the frame can view.
struct DecodedDepth {
  int64_t utime = 0;
  int64_t frame_id = 0;
  runtime::PinholeCamera camera;
  Eigen::Isometry3d T_world_optical = Eigen::Isometry3d::Identity();
  std::vector<uint16_t> pixels;  // row-major millimetres, width * height

  // A view of this object's pixels: valid while it lives and is not modified.
  DepthFrame frame() const { return DepthFrame::view(camera, T_world_optical, pixels, utime); }
};

// Decodes `m` into `out`, reusing its buffer. Returns "" on success, else why the message cannot
// be a depth frame: a camera size that is not positive or beyond kMaxDepthPixels, intrinsics or
// range limits that are not finite and sensible, a pose that is not finite or whose orientation
// is not a unit quaternion (|q| within 1e-3 of 1; it is then normalised), an unknown compression,
// or a payload that is not exactly width * height * 2 bytes (after zlib for ZLIB). The
// integrator's check_frame() applies the remaining checks.
std::string decode_depth(const semx::depth_image_t& m, DecodedDepth& out);
// The message a simulator publishes for `frame` (tests and tools; runtime::depth_image_message),
// zlib when `compress`.
semx::depth_image_t depth_message(const DepthFrame& frame, bool compress = false, int64_t frame_id = 0);

// ---- ODOMETRY (odometry_t) ----

// A finite position within 1e5 m (all the mapper uses of odometry: where to centre the ESDF).
bool accept_odometry(const semx::odometry_t& m);

}  // namespace semx::mapper
