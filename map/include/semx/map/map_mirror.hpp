// A client's copy of the mapper's map, kept from MAP_UPDATE deltas and MAP_SNAPSHOTs (the map
// client library: the planner, semantics and tools link it).
//
// It applies delta s only when it holds s - 1. Any other delta (a gap, or a sequence that went
// backwards because the mapper restarted) means the copy can no longer be trusted: it stops
// applying deltas, says needs_snapshot() (the node then sends MAP_REQUEST), and keeps the deltas
// it receives meanwhile so that, once a snapshot at s arrives, it applies the buffered s + 1,
// s + 2, ... and is current without waiting for another frame.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "semx/map/map_delta.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/map/state_grid.hpp"

namespace semx::map {

class MapMirror {
 public:
  enum class DeltaResult {
    kApplied,   // the mirror is now at delta.seq
    kBuffered,  // out of sequence: kept for after the next snapshot; needs_snapshot() is true
    kRejected,  // wrong resolution or malformed (key out of range): dropped
    kIgnored,   // a map the mirror holds already (a snapshot of a later map came first)
  };
  enum class SnapshotResult {
    kApplied,
    kIgnored,   // not needed and not newer than what the mirror holds
    kRejected,  // malformed or wrong resolution; the mirror is unchanged
  };

  // max_buffered: deltas kept while waiting for a snapshot (oldest dropped beyond it).
  explicit MapMirror(double resolution, size_t max_buffered = 256);

  DeltaResult apply(const MapDelta& delta);
  SnapshotResult apply(const MapSnapshot& snapshot);

  // The delta apply(delta) applied last, with each change's previous state filled in.
  const MapDelta& last_applied() const { return last_applied_; }
  // Sequence of the last delta applied (0: the empty map, before any delta).
  int64_t seq() const { return seq_; }
  bool needs_snapshot() const { return needs_snapshot_; }
  const StateGrid& grid() const { return grid_; }
  double resolution() const { return grid_.resolution(); }
  // Why the last delta or snapshot was rejected.
  const std::string& last_error() const { return last_error_; }

  struct Counters {
    int64_t deltas_applied = 0;
    int64_t deltas_buffered = 0;
    int64_t deltas_rejected = 0;
    int64_t deltas_ignored = 0;
    int64_t gaps = 0;  // times the mirror found itself out of sequence
    int64_t snapshots_applied = 0;
    int64_t snapshots_ignored = 0;
    int64_t snapshots_rejected = 0;
  };
  const Counters& counters() const { return counters_; }

  // ---- the map's queries (StateGrid semantics, identical to the mapper's) ----
  VoxelState state(const VoxelKey& k) const { return grid_.state(k); }
  VoxelState state(const Eigen::Vector3d& p) const { return grid_.state(p); }
  bool is_frontier(const VoxelKey& k) const { return grid_.is_frontier(k); }
  bool is_surface(const VoxelKey& k) const { return grid_.is_surface(k); }
  bool is_visible(const Eigen::Vector3d& from, const Eigen::Vector3d& to, bool unknown_blocks = false) const {
    return grid_.is_visible(from, to, unknown_blocks);
  }
  bool box_collides(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    bool unknown_is_occupied = true) const {
    return grid_.box_collides(lo, hi, unknown_is_occupied);
  }
  int64_t count_frontiers() const { return grid_.count_frontiers(); }

 private:
  bool valid(const MapDelta& d);
  void apply_changes(const MapDelta& d);
  void drain_buffer();

  StateGrid grid_;
  MapDelta last_applied_;
  int64_t seq_ = 0;
  int64_t last_delta_seq_ = 0;  // seq_ may be a snapshot's, ahead of the updates applied
  bool needs_snapshot_ = false;
  size_t max_buffered_;
  std::map<int64_t, MapDelta> buffer_;
  std::string last_error_;
  Counters counters_;
};

}  // namespace semx::map
