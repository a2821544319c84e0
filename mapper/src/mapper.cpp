#include "semx/mapper/mapper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace semx::mapper {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
const MapperConfig& validated(const MapperConfig& c) {
  validate(c);
  return c;
}
}  // namespace

Mapper::Mapper(const MapperConfig& config)
    : config_(validated(config)),
      map_(config.occupancy),
      integrator_(config.integration),
      esdf_(config.esdf, config.occupancy.resolution) {}

FrameResult Mapper::integrate(const DepthFrame& frame) {
  FrameResult r;
  const auto t0 = std::chrono::steady_clock::now();
  r.report = integrator_.integrate(frame, map_, &r.delta.changes);
  r.integrate_ms = ms_since(t0);
  if (!r.report.accepted) {
    ++frames_rejected_;
    return r;
  }
  ++frames_integrated_;
  last_integrate_ms_ = r.integrate_ms;
  r.delta.seq = ++seq_;
  r.delta.utime = frame.utime;
  r.delta.resolution = map_.resolution();
  esdf_dirty_.include(r.report.changed_bounds);
  totals_.pixels += r.report.pixels;
  totals_.hits += r.report.hits;
  totals_.no_return += r.report.no_return;
  totals_.beyond_range += r.report.beyond_range;
  totals_.too_near += r.report.too_near;
  totals_.invalid += r.report.invalid;
  totals_.rays_walked += r.report.rays_walked;
  totals_.voxels_updated += r.report.voxels_updated;
  totals_.voxels_changed += r.report.voxels_changed;
  totals_.out_of_bounds += r.report.out_of_bounds;
  return r;
}

bool Mapper::update_esdf(const Eigen::Vector3d& center, bool force) {
  if (!config_.esdf.enabled) return false;
  const auto t0 = std::chrono::steady_clock::now();
  const bool recomputed = esdf_.update(map_.grid(), center, esdf_dirty_, seq_, force || esdf_stale_);
  if (recomputed) {
    esdf_ms_ = ms_since(t0);
    esdf_dirty_ = map::KeyBox();
    esdf_stale_ = false;
  }
  return recomputed;
}

map::MapStats Mapper::stats(bool count_frontiers) const {
  map::MapStats s = map::compute_stats(map_.grid(), seq_, count_frontiers);
  s.frames_integrated = frames_integrated_;
  s.frames_rejected = frames_rejected_;
  s.integrate_ms = last_integrate_ms_;
  return s;
}

CheckpointInfo Mapper::save_checkpoint(const std::string& path, int64_t utime) const {
  return mapper::save_checkpoint(map_, seq_, utime, path);
}

CheckpointInfo Mapper::load_checkpoint(const std::string& path) {
  CheckpointInfo info = mapper::load_checkpoint(path, map_);
  seq_ = info.seq + kRestoreSequenceJump;
  esdf_stale_ = true;
  return info;
}

void Mapper::replay_delta(const map::MapDelta& delta) {
  if (std::abs(delta.resolution - map_.resolution()) > 1e-9 * map_.resolution()) {
    throw MapIoError("map delta " + std::to_string(delta.seq) + " has " + std::to_string(delta.resolution) +
                     " m voxels, the map " + std::to_string(map_.resolution()) + " m");
  }
  // Values that classify as the state whatever the threshold.
  const float occupied = std::max(map_.hit_log_odds(), map_.threshold_log_odds());
  const float free = std::min(map_.miss_log_odds(),
                              std::nextafter(map_.threshold_log_odds(), -std::numeric_limits<float>::infinity()));
  for (const map::VoxelChange& c : delta.changes) {
    switch (c.state) {
      case map::VoxelState::kOccupied:
        map_.set_log_odds(c.key, occupied);
        break;
      case map::VoxelState::kFree:
        map_.set_log_odds(c.key, free);
        break;
      default:
        map_.set_log_odds(c.key, std::numeric_limits<float>::quiet_NaN());
        break;
    }
  }
  esdf_stale_ = true;
}

}  // namespace semx::mapper
