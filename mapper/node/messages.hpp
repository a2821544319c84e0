// Conversions between the mapper's values and its LCM messages (docs/messages.md), and the
// content checks the node's subscriptions use as `accept` predicates. The mapper library knows
// no messages; this file is the only place that knows both.
//
// Everything here needs only semx_map_client (no log-odds, no OctoMap), so any process that
// keeps a copy of the map links it through semx_map_client_node.
#pragma once

#include <semx/depth_image_t.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/map_request_t.hpp>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_stats_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/odometry_t.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/runtime/camera_info.hpp"
#include "semx/mapper/depth_frame.hpp"
#include "semx/mapper/esdf_grid.hpp"
#include "semx/mapper/map_delta.hpp"
#include "semx/mapper/map_snapshot.hpp"
#include "semx/mapper/map_stats.hpp"

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
// The message a simulator publishes for `frame` (tests and tools), zlib level 1 when `compress`.
semx::depth_image_t depth_message(const DepthFrame& frame, bool compress = false, int64_t frame_id = 0);

// ---- MAP_UPDATE (map_update_t) ----

semx::map_update_t to_message(const MapDelta& d);
// False (and `out` unspecified) when the arrays disagree with num_voxels, a state is not 0..2 or
// the resolution is not finite and positive.
bool from_message(const semx::map_update_t& m, MapDelta& out);
bool accept_update(const semx::map_update_t& m);

// ---- MAP_SNAPSHOT (map_snapshot_t) ----

semx::map_snapshot_t to_message(const MapSnapshot& s);
MapSnapshot from_message(const semx::map_snapshot_t& m);
// Sizes and resolution only; the payload is checked when it is decoded (MapMirror).
bool accept_snapshot(const semx::map_snapshot_t& m);

// ---- MAP_REQUEST (map_request_t) ----

semx::map_request_t request_message(const std::string& requester, int64_t last_seq, int64_t utime);
bool accept_request(const semx::map_request_t& m);

// ---- MAP_STATS (map_stats_t) ----

semx::map_stats_t to_message(const MapStats& s, int64_t utime);

// ---- ESDF_LOCAL (esdf_local_t) ----

// origin = the window's minimum corner in metres (EsdfGrid::origin_point()).
semx::esdf_local_t to_message(const EsdfGrid& g, int64_t utime);
// The inverse (the origin key is the corner divided by the resolution, rounded); false for
// inconsistent sizes or values that are not finite.
bool from_message(const semx::esdf_local_t& m, EsdfGrid& out);

// ---- ODOMETRY (odometry_t) ----

// A finite position within 1e5 m (all the mapper uses of odometry: where to centre the ESDF).
bool accept_odometry(const semx::odometry_t& m);

}  // namespace semx::mapper
