#include "semantics_messages.hpp"

#include <zlib.h>

#include <cmath>

#include "semx/runtime/camera_info.hpp"
#include "semx/runtime/image_codec.hpp"

namespace semx::semantics {

namespace {

std::size_t pixels(const semx::camera_info_t& i) { return static_cast<std::size_t>(i.width) * i.height; }

// Sizes a payload of `expected` raw bytes (pixels of `pixel_bytes`) can have under its codec.
bool payload_ok(int8_t compression, int32_t declared, std::size_t actual, std::size_t expected,
                std::size_t pixel_bytes) {
  using runtime::ImageCompression;
  if (declared < 0 || static_cast<std::size_t>(declared) != actual) return false;
  switch (static_cast<ImageCompression>(compression)) {
    case ImageCompression::kNone:
      return actual == expected;
    case ImageCompression::kZlib:
      return actual > 0 && actual <= compressBound(static_cast<uLong>(expected));
    case ImageCompression::kRle:  // [pixel size] then runs of (uint16 count, pixel)
      return actual > 1 && actual <= 1 + (expected / pixel_bytes) * (2 + pixel_bytes);
  }
  return false;
}

}  // namespace

bool well_formed(const semx::camera_info_t& i) {
  runtime::PinholeCamera camera;
  Eigen::Isometry3d pose;
  if (!runtime::from_camera_info(i, camera, pose).empty()) return false;
  // The semantics library's own limit per side (validate()).
  return i.width <= kMaxImageSide && i.height <= kMaxImageSide;
}

bool accept_depth(const semx::depth_image_t& m) {
  return well_formed(m.info) &&
         payload_ok(m.compression, m.num_depth_bytes, m.depth_data.size(), 2 * pixels(m.info), 2);
}

bool accept_labels(const semx::label_image_t& m) {
  return well_formed(m.info) &&
         payload_ok(m.label_compression, m.num_label_bytes, m.label_data.size(), 4 * pixels(m.info), 4);
}

bool accept_rgb(const semx::rgb_image_t& m) {
  return well_formed(m.info) &&
         payload_ok(m.rgb_compression, m.num_rgb_bytes, m.rgb_data.size(), 3 * pixels(m.info), 3);
}

bool decode_payload(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected,
                    std::vector<uint8_t>& out) {
  return runtime::decode_image(compression, payload, expected, out);
}

void set_camera(const semx::camera_info_t& i, int64_t utime, Frame& f) {
  f.utime = utime;
  f.frame_id = i.frame_id;
  runtime::from_camera_info(i, f.camera, f.pose);
}

bool fill_depth(const semx::depth_image_t& m, Frame& f) {
  return runtime::decode_u16_image(m.compression, m.depth_data, pixels(m.info), f.depth).empty();
}

bool fill_labels(const semx::label_image_t& m, Frame& f) {
  static thread_local std::vector<uint8_t> raw;
  const std::size_t n = pixels(m.info);
  if (!decode_payload(m.label_compression, m.label_data, 4 * n, raw)) return false;
  f.class_label.resize(n);
  f.instance_label.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const uint8_t* p = raw.data() + 4 * i;
    f.class_label[i] = static_cast<uint16_t>(p[0] | (p[1] << 8));
    f.instance_label[i] = static_cast<uint16_t>(p[2] | (p[3] << 8));
  }
  return true;
}

bool fill_rgb(const semx::rgb_image_t& m, Frame& f) {
  return decode_payload(m.rgb_compression, m.rgb_data, 3 * pixels(m.info), f.rgb);
}

semx::semantic_regions_t to_message(const std::vector<Region>& regions, int64_t utime, int64_t seq) {
  semx::semantic_regions_t m{};
  m.utime = utime;
  m.seq = seq;
  m.num_regions = static_cast<int32_t>(regions.size());
  for (const Region& r : regions) {
    semx::semantic_region_t s{};
    s.id = r.id;
    s.class_id = static_cast<int16_t>(r.cls);
    s.label = std::string(runtime::class_info(r.cls).name);
    s.instance = r.instance;
    for (int a = 0; a < 3; ++a) {
      s.centroid[a] = r.centroid[a];
      s.extent[a] = r.extent[a];
    }
    s.weight = r.weight;
    s.radius = r.radius;
    s.confidence = r.confidence;
    s.observations = r.observations;
    s.observed_fraction = r.observed_fraction;
    s.active = r.active;
    m.regions.push_back(std::move(s));
  }
  return m;
}

std::vector<Region> from_message(const semx::semantic_regions_t& m) {
  std::vector<Region> out;
  for (const auto& s : m.regions) {
    Region r;
    r.id = s.id;
    r.cls = runtime::class_from_id(s.class_id).value_or(runtime::SemanticClass::kNone);
    r.instance = static_cast<uint16_t>(s.instance);
    r.centroid = Eigen::Vector3d(s.centroid[0], s.centroid[1], s.centroid[2]);
    r.extent = Eigen::Vector3d(s.extent[0], s.extent[1], s.extent[2]);
    r.weight = s.weight;
    r.radius = s.radius;
    r.confidence = s.confidence;
    r.observations = s.observations;
    r.observed_fraction = s.observed_fraction;
    r.active = s.active;
    out.push_back(r);
  }
  return out;
}

}  // namespace semx::semantics
