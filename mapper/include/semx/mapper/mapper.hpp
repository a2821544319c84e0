// The mapper process's logic in one object, for a thin LCM node to drive:
//
//   Mapper mapper(config);                     // or load_checkpoint() first
//   on CAMERA_DEPTH:  auto r = mapper.integrate(frame);      -> publish r.delta as MAP_UPDATE
//                     mapper.update_esdf(vehicle_position);  -> publish mapper.esdf() as ESDF_LOCAL
//   on MAP_REQUEST, every snapshot_period:  mapper.snapshot(utime)        -> MAP_SNAPSHOT
//   every stats_period:                     mapper.stats()                -> MAP_STATS
//   every checkpoint.period:                mapper.save_checkpoint(path, utime)
//
// Nothing here reads the wall clock for its logic (integrate_ms is measured for monitoring).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "semx/map/map_delta.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/map/map_stats.hpp"
#include "semx/mapper/checkpoint.hpp"
#include "semx/mapper/depth_integrator.hpp"
#include "semx/mapper/esdf_builder.hpp"
#include "semx/mapper/mapper_config.hpp"
#include "semx/mapper/occupancy_map.hpp"

namespace semx::mapper {

struct FrameResult {
  IntegrationReport report;
  map::MapDelta delta;  // meaningful when report.accepted; publish it even when it has no changes
  double integrate_ms = 0.0;
};

class Mapper {
 public:
  // After a restore, sequence numbers continue this far above the checkpoint's, so every client
  // (whose copy may hold deltas the checkpoint lost) sees a gap and resynchronises by snapshot.
  static constexpr int64_t kRestoreSequenceJump = int64_t{1} << 32;

  // Throws runtime::ConfigError for an invalid config.
  explicit Mapper(const MapperConfig& config);

  const MapperConfig& config() const { return config_; }
  const OccupancyMap& map() const { return map_; }
  int64_t seq() const { return seq_; }

  // Integrates one frame. An accepted frame always yields the next delta (seq() + 1); a
  // rejected one (report.error says why) changes nothing and is counted.
  FrameResult integrate(const DepthFrame& frame);

  // Brings the ESDF window (centred on `center`, usually the vehicle) up to date with the map.
  // Returns whether it recomputed; false also when the ESDF is disabled.
  bool update_esdf(const Eigen::Vector3d& center, bool force = false);
  const map::EsdfGrid& esdf() const { return esdf_.grid(); }
  double esdf_ms() const { return esdf_ms_; }

  map::MapSnapshot snapshot(int64_t utime = 0) const {
    return map::encode_snapshot(map_.grid(), seq_, utime);
  }
  // count_frontiers visits the whole map (a few ms for a house); MAP_STATS at 1 Hz can afford it.
  map::MapStats stats(bool count_frontiers = true) const;

  CheckpointInfo save_checkpoint(const std::string& path, int64_t utime) const;
  // Replaces the map with the checkpoint's (throws MapIoError, leaving the map as it was).
  CheckpointInfo load_checkpoint(const std::string& path);

  // Replays a delta this mapper published after its last checkpoint (the node's journal): each
  // changed voxel gets the log-odds of one observation of its new state (one hit for occupied,
  // one miss for free), so the map's states are those the clients were sent, while the log-odds
  // of those voxels are approximate (the rest are the checkpoint's, exact). The sequence is left
  // as it is (a restore's jump). Throws MapIoError for a delta of another resolution.
  void replay_delta(const map::MapDelta& delta);

  int64_t frames_integrated() const { return frames_integrated_; }
  int64_t frames_rejected() const { return frames_rejected_; }
  // Pixel outcomes summed over all accepted frames.
  const IntegrationReport& totals() const { return totals_; }

 private:
  MapperConfig config_;
  OccupancyMap map_;
  DepthIntegrator integrator_;
  EsdfBuilder esdf_;
  int64_t seq_ = 0;
  map::KeyBox esdf_dirty_;   // voxels changed since the last ESDF update
  bool esdf_stale_ = false;  // the whole map was replaced
  double esdf_ms_ = 0.0;
  double last_integrate_ms_ = 0.0;
  int64_t frames_integrated_ = 0;
  int64_t frames_rejected_ = 0;
  IntegrationReport totals_;
};

}  // namespace semx::mapper
