#include "simulator_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "semx/runtime/camera_info.hpp"

namespace semx::simulator {

namespace {

void put_vec(double out[3], const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

// The kRle payload of an RGB image given as its maximal runs: the runs are the payload's
// records, split at the 16-bit count. Byte for byte the payload of runtime::encode_image on the
// image; returns its size, or 0 where encode_image would fall back to raw bytes (or the runs do
// not cover exactly `pixels`).
std::size_t rle_rgb_runs(const std::vector<RgbRun>& runs, std::size_t pixels, std::vector<uint8_t>& out) {
  constexpr std::size_t kPixel = 3, kRecord = 2 + kPixel, kMaxRun = 0xFFFF;
  const std::size_t raw_size = pixels * kPixel;
  if (raw_size < kRecord + 1) return 0;
  if (out.size() < raw_size + 1) out.resize(raw_size + 1);
  uint8_t* const o = out.data();
  std::size_t at = 0, covered = 0;
  o[at++] = kPixel;
  for (const RgbRun& r : runs) {
    covered += r.length;
    for (std::size_t left = r.length; left > 0;) {
      const std::size_t n = std::min(left, kMaxRun);
      if (at > raw_size - kRecord) return 0;  // the rule of encode_image: smaller than raw or raw
      o[at++] = static_cast<uint8_t>(n & 0xFF);
      o[at++] = static_cast<uint8_t>(n >> 8);
      o[at++] = r.colour.r;
      o[at++] = r.colour.g;
      o[at++] = r.colour.b;
      left -= n;
    }
  }
  return covered == pixels ? at : 0;
}

// The kRle payload (runtime/image_codec.hpp) of the label image, whose pixels are the
// little-endian (class, instance) pairs, read straight from the two planes rather than from an
// interleaved copy: that copy (1.2 MB a frame) cost more than the encoding. Byte for byte the
// payload of runtime::encode_image on the interleaved image; returns its size, or 0 where
// encode_image would fall back to raw bytes.
std::size_t rle_label_pairs(const uint16_t* cls, const uint16_t* inst, std::size_t n,
                            std::vector<uint8_t>& out) {
  constexpr std::size_t kPixel = 4, kRecord = 2 + kPixel, kMaxRun = 0xFFFF;
  const std::size_t raw_size = n * kPixel;
  if (raw_size < kRecord + 1) return 0;
  if (out.size() < raw_size + 1) out.resize(raw_size + 1);
  uint8_t* const o = out.data();
  std::size_t at = 0;
  o[at++] = kPixel;
  auto put16 = [&](uint16_t v) {
    o[at++] = static_cast<uint8_t>(v & 0xFF);
    o[at++] = static_cast<uint8_t>(v >> 8);
  };
  for (std::size_t i = 0; i < n;) {
    // Pixel i + k + 1 extends the run when it equals pixel i + k; `check` such k may be tested.
    const std::size_t check = std::min(n - 1 - i, kMaxRun - 1);
    std::size_t k = 0;
#if defined(__SSE2__)
    for (; k + 8 <= check; k += 8) {
      auto load = [](const uint16_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); };
      const __m128i same = _mm_and_si128(_mm_cmpeq_epi16(load(cls + i + k), load(cls + i + k + 1)),
                                         _mm_cmpeq_epi16(load(inst + i + k), load(inst + i + k + 1)));
      const unsigned differ = static_cast<unsigned>(_mm_movemask_epi8(same)) ^ 0xFFFFu;
      if (differ) {
        k += static_cast<std::size_t>(__builtin_ctz(differ)) / 2;
        break;
      }
    }
#endif
    while (k < check && cls[i + k] == cls[i + k + 1] && inst[i + k] == inst[i + k + 1]) ++k;
    const std::size_t run = k + 1;
    if (at > raw_size - kRecord) return 0;  // the rule of encode_image: smaller than raw or raw
    put16(static_cast<uint16_t>(run));
    put16(cls[i]);
    put16(inst[i]);
    i += run;
  }
  return at;
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
  return runtime::depth_image_message(f.camera, f.pose, f.depth.data.data(), f.depth.data.size(), f.utime,
                                      f.frame_id, codec);
}

semx::rgb_image_t rgb_message(const CameraFrame& f, runtime::ImageCompression codec) {
  semx::rgb_image_t m{};
  m.utime = f.utime;
  m.info = camera_info(f);
  static_assert(sizeof(Rgb) == 3, "Rgb is three packed bytes");
  const std::size_t pixels = static_cast<std::size_t>(f.camera.width) * f.camera.height;
  const bool runs = (f.channels & kRenderRgbRuns) && !(f.channels & kRenderRgb);
  if (runs && codec == runtime::ImageCompression::kRle) {
    thread_local std::vector<uint8_t> rle;
    const std::size_t size = rle_rgb_runs(f.rgb_runs, pixels, rle);
    if (size > 0) {
      m.rgb_data.assign(rle.begin(), rle.begin() + static_cast<std::ptrdiff_t>(size));
      m.rgb_compression = static_cast<int8_t>(runtime::ImageCompression::kRle);
      m.num_rgb_bytes = static_cast<int32_t>(size);
      return m;
    }
  }
  const uint8_t* raw = reinterpret_cast<const uint8_t*>(f.rgb.data.data());
  std::size_t raw_size = f.rgb.data.size() * 3;
  thread_local std::vector<uint8_t> expanded;
  if (runs) {
    // Rare (another codec, or runs too short for RLE to pay): the image is needed after all.
    expanded.resize(pixels * 3);
    std::size_t at = 0;
    for (const RgbRun& r : f.rgb_runs) {
      for (uint32_t k = 0; k < r.length && at < pixels; ++k, ++at)
        std::memcpy(&expanded[3 * at], &r.colour, 3);
    }
    raw = expanded.data();
    raw_size = expanded.size();
    // RLE reaches here only when it would not shrink the image, and then sends it raw too.
    if (codec == runtime::ImageCompression::kRle) codec = runtime::ImageCompression::kNone;
  }
  runtime::ImageCompression used;
  m.rgb_data = runtime::encode_image(raw, raw_size, 3, codec, used);
  m.rgb_compression = static_cast<int8_t>(used);
  m.num_rgb_bytes = static_cast<int32_t>(m.rgb_data.size());
  return m;
}

semx::label_image_t label_message(const CameraFrame& f, runtime::ImageCompression codec) {
  semx::label_image_t m{};
  m.utime = f.utime;
  m.info = camera_info(f);
  const std::size_t n = f.class_label.data.size();
  const uint16_t* cls = f.class_label.data.data();
  const uint16_t* inst = f.instance_label.data.data();
  if (codec == runtime::ImageCompression::kRle) {
    // Reused across frames: growing a fresh 1.2 MB buffer per frame costs more in page faults
    // than the encoding itself.
    thread_local std::vector<uint8_t> rle;
    const std::size_t size = rle_label_pairs(cls, inst, n, rle);
    if (size > 0) {
      m.label_data.assign(rle.begin(), rle.begin() + static_cast<std::ptrdiff_t>(size));
      m.label_compression = static_cast<int8_t>(runtime::ImageCompression::kRle);
      m.num_label_bytes = static_cast<int32_t>(size);
      return m;
    }
  }
  thread_local std::vector<uint8_t> raw;
  raw.resize(n * 4);
  uint8_t* out = raw.data();
  for (std::size_t i = 0; i < n; ++i) {
    // Little-endian class then instance, whatever the host: one 32-bit store per pixel.
    uint32_t v = static_cast<uint32_t>(cls[i]) | static_cast<uint32_t>(inst[i]) << 16;
    if constexpr (__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__) v = __builtin_bswap32(v);
    std::memcpy(out + 4 * i, &v, 4);
  }
  runtime::ImageCompression used;
  // RLE reaches here only when it would not shrink the image, and then sends it raw too.
  m.label_data = runtime::encode_image(
      raw, 4, codec == runtime::ImageCompression::kRle ? runtime::ImageCompression::kNone : codec, used);
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
