// camera_info_t <-> the camera model and pose, for every process that sends or reads camera
// frames (simulator, mapper, semantics), so validation and conventions exist once.
#pragma once

#include <semx/camera_info_t.hpp>
#include <semx/depth_image_t.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/runtime/image_codec.hpp"
#include "semx/runtime/pinhole_camera.hpp"

namespace semx::runtime {

// Frames larger than this are not from any camera semx models (and would be a memory attack).
inline constexpr int64_t kMaxCameraPixels = int64_t{1} << 24;

semx::camera_info_t to_camera_info(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_optical,
                                   int64_t frame_id);

// Reads a camera_info_t; returns "" when usable, else why not: size not positive or above
// kMaxCameraPixels, intrinsics not finite and positive, range limits not 0 <= min < max, position
// not finite or beyond 1e5 m, orientation not a unit quaternion (within 1e-3; it is normalised).
std::string from_camera_info(const semx::camera_info_t& info, PinholeCamera& camera,
                             Eigen::Isometry3d& T_world_optical);

// The CAMERA_DEPTH message of `pixels` (row-major millimetres, camera.width * camera.height of
// them) seen from T_world_optical: the simulator's frames and the tests' are encoded here alone.
// The payload is little-endian whatever the host, with `codec` (raw when it would not shrink).
semx::depth_image_t depth_image_message(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_optical,
                                        const uint16_t* pixels, std::size_t count, int64_t utime,
                                        int64_t frame_id, ImageCompression codec);

// Decodes a uint16 image payload (any image codec) of `pixels` pixels into host-order values.
std::string decode_u16_image(int8_t compression, const std::vector<uint8_t>& payload, std::size_t pixels,
                             std::vector<uint16_t>& out);

}  // namespace semx::runtime
