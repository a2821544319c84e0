#include "frame_messages.hpp"

#include <cmath>

#include <cstring>
#include "semx/runtime/camera_info.hpp"

namespace semx::simulator {

namespace {

void put_vec(double out[3], const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

// Little-endian bytes of a uint16 image (the wire format whatever the host).
std::vector<uint8_t> le_bytes(const std::vector<uint16_t>& a) {
  std::vector<uint8_t> out(a.size() * 2);
  for (std::size_t i = 0; i < a.size(); ++i) {
    out[2 * i] = static_cast<uint8_t>(a[i] & 0xFF);
    out[2 * i + 1] = static_cast<uint8_t>(a[i] >> 8);
  }
  return out;
}

}  // namespace

semx::odometry_t to_message(const OdometrySample& s) {
  semx::odometry_t m{};
  m.utime = s.utime;
  put_vec(m.position, s.position);
  m.orientation[0] = s.orientation.w();
  m.orientation[1] = s.orientation.x();
  m.orientation[2] = s.orientation.y();
  m.orientation[3] = s.orientation.z();
  put_vec(m.velocity, s.velocity);
  put_vec(m.angular_velocity, s.angular_velocity);
  return m;
}

semx::imu_t to_message(const ImuSample& s) {
  semx::imu_t m{};
  m.utime = s.utime;
  put_vec(m.linear_acceleration, s.linear_acceleration);
  put_vec(m.angular_velocity, s.angular_velocity);
  return m;
}

semx::camera_info_t camera_info(const CameraFrame& f) {
  return runtime::to_camera_info(f.camera, f.pose, f.frame_id);
}

semx::depth_image_t depth_message(const CameraFrame& f, runtime::ImageCompression codec) {
  semx::depth_image_t m{};
  m.utime = f.utime;
  m.info = camera_info(f);
  runtime::ImageCompression used;
  if constexpr (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) {
    m.depth_data = runtime::encode_image(reinterpret_cast<const uint8_t*>(f.depth.data.data()),
                                         f.depth.data.size() * 2, 2, codec, used);
  } else {
    m.depth_data = runtime::encode_image(le_bytes(f.depth.data), 2, codec, used);
  }
  m.compression = static_cast<int8_t>(used);
  m.num_depth_bytes = static_cast<int32_t>(m.depth_data.size());
  return m;
}

semx::rgb_image_t rgb_message(const CameraFrame& f, runtime::ImageCompression codec) {
  semx::rgb_image_t m{};
  m.utime = f.utime;
  m.info = camera_info(f);
  static_assert(sizeof(Rgb) == 3, "Rgb is three packed bytes");
  runtime::ImageCompression used;
  m.rgb_data = runtime::encode_image(reinterpret_cast<const uint8_t*>(f.rgb.data.data()),
                                     f.rgb.data.size() * 3, 3, codec, used);
  m.rgb_compression = static_cast<int8_t>(used);
  m.num_rgb_bytes = static_cast<int32_t>(m.rgb_data.size());
  return m;
}

semx::label_image_t label_message(const CameraFrame& f, runtime::ImageCompression codec) {
  semx::label_image_t m{};
  m.utime = f.utime;
  m.info = camera_info(f);
  const std::size_t n = f.class_label.data.size();
  // Reused across frames: a fresh 1.2 MB buffer per frame costs more in page faults than the
  // packing itself.
  thread_local std::vector<uint8_t> raw;
  raw.resize(n * 4);
  const uint16_t* cls = f.class_label.data.data();
  const uint16_t* inst = f.instance_label.data.data();
  uint8_t* out = raw.data();
  for (std::size_t i = 0; i < n; ++i) {
    // Little-endian class then instance, whatever the host: one 32-bit store per pixel.
    uint32_t v = static_cast<uint32_t>(cls[i]) | static_cast<uint32_t>(inst[i]) << 16;
    if constexpr (__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__) v = __builtin_bswap32(v);
    std::memcpy(out + 4 * i, &v, 4);
  }
  runtime::ImageCompression used;
  m.label_data = runtime::encode_image(raw, 4, codec, used);
  m.label_compression = static_cast<int8_t>(used);
  m.num_label_bytes = static_cast<int32_t>(m.label_data.size());
  return m;
}

bool well_formed(const semx::control_cmd_t& m) {
  if (m.mode < semx::control_cmd_t::HOLD || m.mode > semx::control_cmd_t::ACCELERATION) return false;
  if (m.yaw_mode != semx::control_cmd_t::YAW_ANGLE && m.yaw_mode != semx::control_cmd_t::YAW_RATE)
    return false;
  for (double v : m.setpoint) {
    if (!std::isfinite(v)) return false;
  }
  return std::isfinite(m.yaw) && std::isfinite(m.yaw_rate);
}

ControlCommand from_message(const semx::control_cmd_t& m) {
  ControlCommand c;
  c.mode = m.mode;
  c.setpoint = Eigen::Vector3d(m.setpoint[0], m.setpoint[1], m.setpoint[2]);
  c.yaw_mode = m.yaw_mode;
  c.yaw = m.yaw;
  c.yaw_rate = m.yaw_rate;
  return c;
}

bool image_bytes(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected_bytes,
                 std::vector<uint8_t>& out) {
  return runtime::decode_image(compression, payload, expected_bytes, out);
}

}  // namespace semx::simulator
