#include "map_messages.hpp"

#include <zlib.h>

#include <Eigen/Geometry>
#include <cmath>

#include "semx/map/voxel_key.hpp"
#include "semx/runtime/camera_info.hpp"

namespace semx::map {

namespace {

bool finite3(const double v[3]) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

// Positions further out than this are not a vehicle's (the integrator's own limit).
constexpr double kMaxCoordinate = 1e5;

}  // namespace

// ---- MAP_UPDATE ----

semx::map_update_t to_message(const MapDelta& d) {
  semx::map_update_t m{};
  m.utime = d.utime;
  m.seq = d.seq;
  m.resolution = d.resolution;
  const size_t n = d.changes.size();
  m.num_voxels = static_cast<int32_t>(n);
  m.key_x.resize(n);
  m.key_y.resize(n);
  m.key_z.resize(n);
  m.state.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const VoxelChange& c = d.changes[i];
    m.key_x[i] = c.key.x;
    m.key_y[i] = c.key.y;
    m.key_z[i] = c.key.z;
    m.state[i] = static_cast<int8_t>(c.state);
  }
  return m;
}

bool accept_update(const semx::map_update_t& m) {
  if (m.num_voxels < 0) return false;
  const size_t n = static_cast<size_t>(m.num_voxels);
  if (m.key_x.size() != n || m.key_y.size() != n || m.key_z.size() != n || m.state.size() != n) return false;
  if (!(std::isfinite(m.resolution) && m.resolution > 0)) return false;
  for (int8_t s : m.state) {
    if (!valid_state_value(s)) return false;
  }
  return true;
}

bool from_message(const semx::map_update_t& m, MapDelta& out) {
  if (!accept_update(m)) return false;
  out.seq = m.seq;
  out.utime = m.utime;
  out.resolution = m.resolution;
  const size_t n = static_cast<size_t>(m.num_voxels);
  out.changes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    out.changes[i].key = VoxelKey(m.key_x[i], m.key_y[i], m.key_z[i]);
    out.changes[i].state = static_cast<VoxelState>(m.state[i]);
  }
  return true;
}

// ---- MAP_SNAPSHOT ----

semx::map_snapshot_t to_message(const MapSnapshot& s) {
  semx::map_snapshot_t m{};
  m.utime = s.utime;
  m.seq = s.seq;
  m.resolution = s.resolution;
  m.encoding = s.encoding;
  m.snapshot_data = s.data;
  m.num_snapshot_bytes = static_cast<int32_t>(s.data.size());
  return m;
}

MapSnapshot from_message(const semx::map_snapshot_t& m) {
  MapSnapshot s;
  s.utime = m.utime;
  s.seq = m.seq;
  s.resolution = m.resolution;
  s.encoding = m.encoding;
  s.data = m.snapshot_data;
  return s;
}

bool accept_snapshot(const semx::map_snapshot_t& m) {
  return m.num_snapshot_bytes >= 0 && m.snapshot_data.size() == static_cast<size_t>(m.num_snapshot_bytes) &&
         std::isfinite(m.resolution) && m.resolution > 0 && m.seq >= 0;
}

// ---- MAP_REQUEST ----

semx::map_request_t request_message(const std::string& requester, int64_t last_seq, int64_t utime) {
  semx::map_request_t m{};
  m.utime = utime;
  m.requester = requester;
  m.last_seq = last_seq;
  return m;
}

bool accept_request(const semx::map_request_t& m) { return m.last_seq >= -1; }

// ---- MAP_STATS ----

semx::map_stats_t to_message(const MapStats& s, int64_t utime) {
  semx::map_stats_t m{};
  m.utime = utime;
  m.seq = s.seq;
  m.resolution = s.resolution;
  m.free_voxels = s.free_voxels;
  m.occupied_voxels = s.occupied_voxels;
  m.frontier_voxels = s.frontier_voxels;
  m.known_m3 = s.known_m3;
  m.free_m3 = s.free_m3;
  m.occupied_m3 = s.occupied_m3;
  for (int i = 0; i < 3; ++i) {
    m.bounds_min[i] = s.bounds_min[i];
    m.bounds_max[i] = s.bounds_max[i];
  }
  m.frames_integrated = s.frames_integrated;
  m.frames_rejected = s.frames_rejected;
  m.integrate_ms = s.integrate_ms;
  return m;
}

// ---- ESDF_LOCAL ----

semx::esdf_local_t to_message(const EsdfGrid& g, int64_t utime) {
  semx::esdf_local_t m{};
  m.utime = utime;
  m.map_seq = g.map_seq;
  m.resolution = g.resolution;
  const Eigen::Vector3d o = g.origin_point();
  for (int i = 0; i < 3; ++i) m.origin[i] = o[i];
  m.nx = g.nx;
  m.ny = g.ny;
  m.nz = g.nz;
  m.unknown_as_occupied = g.unknown_as_occupied ? 1 : 0;
  m.max_distance = g.max_distance;
  m.distance = g.distance;
  m.num_cells = static_cast<int32_t>(g.distance.size());
  return m;
}

bool from_message(const semx::esdf_local_t& m, EsdfGrid& out) {
  if (m.nx <= 0 || m.ny <= 0 || m.nz <= 0) return false;
  const int64_t cells = static_cast<int64_t>(m.nx) * m.ny * m.nz;
  if (cells != m.num_cells || m.distance.size() != static_cast<size_t>(cells)) return false;
  if (!(std::isfinite(m.resolution) && m.resolution > 0 && std::isfinite(m.max_distance) &&
        finite3(m.origin))) {
    return false;
  }
  VoxelKey origin;
  for (int i = 0; i < 3; ++i) {
    const double k = std::round(m.origin[i] / m.resolution);
    if (!(std::abs(k) < kMaxKeyMagnitude)) return false;
    origin[i] = static_cast<int32_t>(k);
  }
  for (float d : m.distance) {
    if (!std::isfinite(d)) return false;
  }
  out.resolution = m.resolution;
  out.origin = origin;
  out.nx = m.nx;
  out.ny = m.ny;
  out.nz = m.nz;
  out.max_distance = m.max_distance;
  out.unknown_as_occupied = m.unknown_as_occupied != 0;
  out.map_seq = m.map_seq;
  out.distance = m.distance;
  return true;
}

}  // namespace semx::map
