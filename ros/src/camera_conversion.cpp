#include "semx/ros/camera_conversion.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace semx::rosbridge {

namespace {

msg::Header optical_header(const CameraShot& shot, const FrameNames& frames, const TimeBase& time) {
  msg::Header h;
  h.stamp_ns = time.to_ros_ns(shot.utime);
  h.frame_id = frames.optical;
  return h;
}

void put_u16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v & 0xFF);
  p[1] = static_cast<uint8_t>(v >> 8);
}

uint16_t get_u16(const uint8_t* p, bool big_endian) {
  return big_endian ? static_cast<uint16_t>((p[0] << 8) | p[1]) : static_cast<uint16_t>(p[0] | (p[1] << 8));
}

float get_f32(const uint8_t* p, bool big_endian) {
  uint8_t b[4];
  for (int i = 0; i < 4; ++i) b[i] = big_endian ? p[3 - i] : p[i];
  float f;
  std::memcpy(&f, b, 4);  // little-endian host (x86, arm64 Linux)
  return f;
}

// An image of the shot's size whose rows hold at least `pixel_bytes` per pixel.
std::string check_layout(const msg::Image& image, const CameraShot& shot, std::size_t pixel_bytes) {
  if (image.width != static_cast<uint32_t>(shot.camera.width) ||
      image.height != static_cast<uint32_t>(shot.camera.height)) {
    return "image is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", CameraInfo says " +
           std::to_string(shot.camera.width) + "x" + std::to_string(shot.camera.height);
  }
  if (static_cast<std::size_t>(image.step) < pixel_bytes * image.width) return "step shorter than a row";
  if (image.data.size() < static_cast<std::size_t>(image.step) * image.height) return "data shorter than step * height";
  return "";
}

msg::Image empty_image(const CameraShot& shot, const FrameNames& frames, const TimeBase& time, const char* encoding,
                       std::size_t pixel_bytes) {
  msg::Image m;
  m.header = optical_header(shot, frames, time);
  m.width = static_cast<uint32_t>(shot.camera.width);
  m.height = static_cast<uint32_t>(shot.camera.height);
  m.encoding = encoding;
  m.is_bigendian = false;
  m.step = static_cast<uint32_t>(pixel_bytes * m.width);
  m.data.resize(static_cast<std::size_t>(m.step) * m.height);
  return m;
}

}  // namespace

msg::CameraInfo to_ros_info(const CameraShot& shot, const FrameNames& frames, const TimeBase& time) {
  msg::CameraInfo m;
  m.header = optical_header(shot, frames, time);
  const runtime::PinholeCamera& c = shot.camera;
  m.width = static_cast<uint32_t>(c.width);
  m.height = static_cast<uint32_t>(c.height);
  m.distortion_model = "plumb_bob";
  m.D.assign(5, 0.0);
  m.K = {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.P = {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0};
  return m;
}

std::string camera_from_ros(const msg::CameraInfo& info, double min_range, double max_range,
                            runtime::PinholeCamera& camera) {
  if (info.width == 0 || info.height == 0 || info.width > (1u << 14) || info.height > (1u << 14)) {
    return "CameraInfo size " + std::to_string(info.width) + "x" + std::to_string(info.height);
  }
  const double fx = info.K[0], fy = info.K[4], cx = info.K[2], cy = info.K[5];
  if (!(std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy) && fx > 0 && fy > 0)) {
    return "CameraInfo K without positive focal lengths";
  }
  if (info.K[1] != 0.0) return "CameraInfo K with skew (not supported)";
  for (double d : info.D) {
    if (d != 0.0) return "CameraInfo with distortion (not supported: rectify the image first)";
  }
  if (!(min_range >= 0 && max_range > min_range)) return "range limits not 0 <= min < max";
  runtime::PinholeCamera c;
  c.width = static_cast<int>(info.width);
  c.height = static_cast<int>(info.height);
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  c.min_range = min_range;
  c.max_range = max_range;
  camera = c;
  return "";
}

msg::Image to_ros(const DepthFrame& f, const FrameNames& frames, const TimeBase& time) {
  msg::Image m = empty_image(f.shot, frames, time, "16UC1", 2);
  const std::size_t n = std::min(f.depth_mm.size(), m.data.size() / 2);
  for (std::size_t i = 0; i < n; ++i) put_u16(&m.data[2 * i], f.depth_mm[i]);
  return m;
}

msg::Image to_ros(const LabelFrame& f, const FrameNames& frames, const TimeBase& time) {
  msg::Image m = empty_image(f.shot, frames, time, "16UC2", 4);
  const std::size_t n = std::min({f.classes.size(), f.instances.size(), m.data.size() / 4});
  for (std::size_t i = 0; i < n; ++i) {
    put_u16(&m.data[4 * i], f.classes[i]);
    put_u16(&m.data[4 * i + 2], f.instances[i]);
  }
  return m;
}

msg::Image to_ros(const RgbFrame& f, const FrameNames& frames, const TimeBase& time) {
  msg::Image m = empty_image(f.shot, frames, time, "rgb8", 3);
  std::memcpy(m.data.data(), f.rgb.data(), std::min(f.rgb.size(), m.data.size()));
  return m;
}

std::string from_ros(const msg::Image& image, const CameraShot& shot, DepthFrame& out) {
  const std::size_t w = image.width, h = image.height;
  std::vector<uint16_t> depth(w * h);
  if (image.encoding == "16UC1" || image.encoding == "mono16") {
    if (std::string why = check_layout(image, shot, 2); !why.empty()) return why;
    for (std::size_t v = 0; v < h; ++v) {
      const uint8_t* row = &image.data[v * image.step];
      for (std::size_t u = 0; u < w; ++u) depth[v * w + u] = get_u16(row + 2 * u, image.is_bigendian);
    }
  } else if (image.encoding == "32FC1") {
    if (std::string why = check_layout(image, shot, 4); !why.empty()) return why;
    for (std::size_t v = 0; v < h; ++v) {
      const uint8_t* row = &image.data[v * image.step];
      for (std::size_t u = 0; u < w; ++u) {
        const float z = get_f32(row + 4 * u, image.is_bigendian);
        uint16_t mm = runtime::kDepthInvalid;
        if (z == std::numeric_limits<float>::infinity()) {
          mm = runtime::kDepthNoReturn;
        } else if (std::isfinite(z) && z > 0.0f) {
          const double r = std::round(static_cast<double>(z) * 1000.0);
          mm = r >= runtime::kDepthMaxEncodable ? runtime::kDepthMaxEncodable
                                               : static_cast<uint16_t>(std::max(1.0, r));
        }
        depth[v * w + u] = mm;
      }
    }
  } else {
    return "depth encoding '" + image.encoding + "' (expected 16UC1, mono16 or 32FC1)";
  }
  out.shot = shot;
  out.depth_mm = std::move(depth);
  return "";
}

std::string from_ros(const msg::Image& image, const CameraShot& shot, LabelFrame& out) {
  const std::size_t w = image.width, h = image.height;
  std::vector<uint16_t> classes(w * h), instances(w * h, 0);
  std::size_t bytes = 0;
  bool two_channels = false;
  if (image.encoding == "16UC2") {
    bytes = 4;
    two_channels = true;
  } else if (image.encoding == "16UC1" || image.encoding == "mono16") {
    bytes = 2;
  } else if (image.encoding == "8UC1" || image.encoding == "mono8") {
    bytes = 1;
  } else {
    return "label encoding '" + image.encoding + "' (expected 16UC2, 16UC1, mono16, 8UC1 or mono8)";
  }
  if (std::string why = check_layout(image, shot, bytes); !why.empty()) return why;
  for (std::size_t v = 0; v < h; ++v) {
    const uint8_t* row = &image.data[v * image.step];
    for (std::size_t u = 0; u < w; ++u) {
      const uint8_t* p = row + bytes * u;
      const std::size_t i = v * w + u;
      classes[i] = bytes == 1 ? p[0] : get_u16(p, image.is_bigendian);
      if (two_channels) instances[i] = get_u16(p + 2, image.is_bigendian);
    }
  }
  out.shot = shot;
  out.classes = std::move(classes);
  out.instances = std::move(instances);
  return "";
}

std::string from_ros(const msg::Image& image, const CameraShot& shot, RgbFrame& out) {
  const bool bgr = image.encoding == "bgr8";
  if (image.encoding != "rgb8" && !bgr) return "colour encoding '" + image.encoding + "' (expected rgb8 or bgr8)";
  if (std::string why = check_layout(image, shot, 3); !why.empty()) return why;
  const std::size_t w = image.width, h = image.height;
  std::vector<uint8_t> rgb(3 * w * h);
  for (std::size_t v = 0; v < h; ++v) {
    const uint8_t* row = &image.data[v * image.step];
    for (std::size_t u = 0; u < w; ++u) {
      uint8_t* q = &rgb[3 * (v * w + u)];
      q[0] = row[3 * u + (bgr ? 2 : 0)];
      q[1] = row[3 * u + 1];
      q[2] = row[3 * u + (bgr ? 0 : 2)];
    }
  }
  out.shot = shot;
  out.rgb = std::move(rgb);
  return "";
}

msg::TransformStamped camera_transform(const CameraShot& shot, const Eigen::Isometry3d& T_world_body,
                                       const FrameNames& frames, const TimeBase& time) {
  const Eigen::Isometry3d T = camera_link_in_body(T_world_body, shot.T_world_optical);
  msg::TransformStamped t;
  t.header.stamp_ns = time.to_ros_ns(shot.utime);
  t.header.frame_id = frames.body;
  t.child_frame_id = frames.camera;
  t.translation = T.translation();
  t.rotation = Eigen::Quaterniond(T.rotation()).normalized();
  return t;
}

msg::TransformStamped optical_transform(const FrameNames& frames, int64_t stamp_ns) {
  msg::TransformStamped t;
  t.header.stamp_ns = stamp_ns;
  t.header.frame_id = frames.camera;
  t.child_frame_id = frames.optical;
  t.rotation = Eigen::Quaterniond(optical_in_camera_link().rotation());
  return t;
}

}  // namespace semx::rosbridge
