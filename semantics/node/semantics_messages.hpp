// Conversions between semx messages and the semantics library: content checks for the camera
// channels (the `accept` predicates of the subscriptions), image payloads into a Frame, regions
// into SEMANTIC_REGIONS. The library knows no messages; the node knows no geometry.
#pragma once

#include <semx/camera_info_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/rgb_image_t.hpp>
#include <semx/semantic_regions_t.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "semx/semantics/frame.hpp"
#include "semx/semantics/regions.hpp"

namespace semx::semantics {

// Camera info a frame can be built from: runtime::from_camera_info's checks (size, finite
// positive intrinsics, 0 <= min_range < max_range, finite position, unit quaternion) and sides
// of at most kMaxImageSide.
bool well_formed(const semx::camera_info_t& info);
// Plus: a known codec (runtime/image_codec.hpp); uncompressed payloads of exactly
// width*height*bytes_per_pixel bytes; encoded ones no larger than their codec can make them.
bool accept_depth(const semx::depth_image_t& m);
bool accept_labels(const semx::label_image_t& m);
bool accept_rgb(const semx::rgb_image_t& m);

// Raw image bytes of a payload (any codec); false unless it decodes to exactly `expected`.
bool decode_payload(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected,
                    std::vector<uint8_t>& out);

// Camera model and pose of a frame (info must be well_formed).
void set_camera(const semx::camera_info_t& info, int64_t utime, Frame& f);
// Image contents into `f` (sizes from its info); false when the payload does not decode.
bool fill_depth(const semx::depth_image_t& m, Frame& f);
bool fill_labels(const semx::label_image_t& m, Frame& f);
bool fill_rgb(const semx::rgb_image_t& m, Frame& f);

semx::semantic_regions_t to_message(const std::vector<Region>& regions, int64_t utime, int64_t seq);
// Back from a message (for tests and tools that listen to SEMANTIC_REGIONS).
std::vector<Region> from_message(const semx::semantic_regions_t& m);

}  // namespace semx::semantics
