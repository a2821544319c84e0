#include "mapper_messages.hpp"

#include <cmath>

namespace semx::mapper {

namespace {

// Positions further out than this are not a vehicle's (the integrator's own limit).
constexpr double kMaxCoordinate = 1e5;

}  // namespace

// ---- CAMERA_DEPTH ----

std::string decode_depth(const semx::depth_image_t& m, DecodedDepth& out) {
  std::string why = runtime::from_camera_info(m.info, out.camera, out.T_world_optical);
  if (!why.empty()) return why;
  if (m.num_depth_bytes < 0 || m.depth_data.size() != static_cast<size_t>(m.num_depth_bytes)) {
    return "num_depth_bytes disagrees with the payload";
  }
  const size_t pixels = static_cast<size_t>(m.info.width) * static_cast<size_t>(m.info.height);
  why = runtime::decode_u16_image(m.compression, m.depth_data, pixels, out.pixels);
  if (!why.empty()) return why;
  out.utime = m.utime;
  out.frame_id = m.info.frame_id;
  return {};
}

semx::depth_image_t depth_message(const DepthFrame& f, bool compress, int64_t frame_id) {
  return runtime::depth_image_message(
      f.camera, f.T_world_optical, f.depth, f.depth_size, f.utime, frame_id,
      compress ? runtime::ImageCompression::kZlib : runtime::ImageCompression::kNone);
}

// ---- ODOMETRY ----

bool accept_odometry(const semx::odometry_t& m) {
  for (double p : m.position) {
    if (!std::isfinite(p) || std::abs(p) > kMaxCoordinate) return false;
  }
  return true;
}

}  // namespace semx::mapper
