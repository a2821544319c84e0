#include "semx/runtime/camera_info.hpp"

#include <cmath>
#include <cstring>

#include "semx/runtime/image_codec.hpp"

namespace semx::runtime {

semx::camera_info_t to_camera_info(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_optical,
                                   int64_t frame_id) {
  semx::camera_info_t info{};
  info.frame_id = frame_id;
  const Eigen::Vector3d t = T_world_optical.translation();
  const Eigen::Quaterniond q(T_world_optical.linear());
  for (int i = 0; i < 3; ++i) info.sensor_position[i] = t[i];
  info.sensor_orientation[0] = q.w();
  info.sensor_orientation[1] = q.x();
  info.sensor_orientation[2] = q.y();
  info.sensor_orientation[3] = q.z();
  info.width = camera.width;
  info.height = camera.height;
  info.fx = camera.fx;
  info.fy = camera.fy;
  info.cx = camera.cx;
  info.cy = camera.cy;
  info.min_range = camera.min_range;
  info.max_range = camera.max_range;
  return info;
}

semx::depth_image_t depth_image_message(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_optical,
                                        const uint16_t* pixels, std::size_t count, int64_t utime,
                                        int64_t frame_id, ImageCompression codec) {
  semx::depth_image_t m{};
  m.utime = utime;
  m.info = to_camera_info(camera, T_world_optical, frame_id);
  ImageCompression used;
  if constexpr (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) {
    m.depth_data = encode_image(reinterpret_cast<const uint8_t*>(pixels), count * 2, 2, codec, used);
  } else {
    std::vector<uint8_t> le(count * 2);
    for (std::size_t i = 0; i < count; ++i) {
      le[2 * i] = static_cast<uint8_t>(pixels[i] & 0xFF);
      le[2 * i + 1] = static_cast<uint8_t>(pixels[i] >> 8);
    }
    m.depth_data = encode_image(le, 2, codec, used);
  }
  m.compression = static_cast<int8_t>(used);
  m.num_depth_bytes = static_cast<int32_t>(m.depth_data.size());
  return m;
}

std::string from_camera_info(const semx::camera_info_t& info, PinholeCamera& camera,
                             Eigen::Isometry3d& T_world_optical) {
  if (info.width <= 0 || info.height <= 0 ||
      static_cast<int64_t>(info.width) * static_cast<int64_t>(info.height) > kMaxCameraPixels) {
    return "camera size " + std::to_string(info.width) + "x" + std::to_string(info.height) +
           " is not positive or too large";
  }
  if (!(std::isfinite(info.fx) && std::isfinite(info.fy) && info.fx > 0 && info.fy > 0 &&
        std::isfinite(info.cx) && std::isfinite(info.cy))) {
    return "camera intrinsics are not finite and positive";
  }
  if (!(std::isfinite(info.min_range) && std::isfinite(info.max_range) && info.min_range >= 0 &&
        info.max_range > info.min_range)) {
    return "camera range limits are not 0 <= min_range < max_range";
  }
  for (double p : info.sensor_position) {
    if (!std::isfinite(p)) return "sensor position is not finite";
    if (std::abs(p) > 1e5) return "sensor position is beyond 1e5 m";
  }
  const double* q = info.sensor_orientation;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(q[i])) return "sensor orientation is not finite";
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= 1e-3)) return "sensor orientation is not a unit quaternion";

  camera.width = info.width;
  camera.height = info.height;
  camera.fx = info.fx;
  camera.fy = info.fy;
  camera.cx = info.cx;
  camera.cy = info.cy;
  camera.min_range = info.min_range;
  camera.max_range = info.max_range;
  T_world_optical = Eigen::Isometry3d::Identity();
  T_world_optical.linear() =
      Eigen::Quaterniond(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm).toRotationMatrix();
  T_world_optical.translation() =
      Eigen::Vector3d(info.sensor_position[0], info.sensor_position[1], info.sensor_position[2]);
  return {};
}

std::string decode_u16_image(int8_t compression, const std::vector<uint8_t>& payload, std::size_t pixels,
                             std::vector<uint16_t>& out) {
  std::vector<uint8_t> bytes;
  std::string error;
  if (!decode_image(compression, payload, pixels * 2, bytes, &error)) return error;
  out.resize(pixels);
  if constexpr (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) {
    std::memcpy(out.data(), bytes.data(), bytes.size());
  } else {
    for (std::size_t i = 0; i < pixels; ++i)
      out[i] = static_cast<uint16_t>(bytes[2 * i] | bytes[2 * i + 1] << 8);
  }
  return {};
}

}  // namespace semx::runtime
