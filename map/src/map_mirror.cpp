#include "semx/map/map_mirror.hpp"

#include <cmath>
#include <cstdlib>

namespace semx::map {

MapMirror::MapMirror(double resolution, size_t max_buffered)
    : grid_(resolution), max_buffered_(max_buffered) {}

bool MapMirror::valid(const MapDelta& d) {
  if (!(std::abs(d.resolution - grid_.resolution()) <= 1e-9 * grid_.resolution())) {
    last_error_ = "delta " + std::to_string(d.seq) + ": resolution " + std::to_string(d.resolution) +
                  " m, mirror has " + std::to_string(grid_.resolution()) + " m";
    return false;
  }
  for (const VoxelChange& c : d.changes) {
    if (std::abs(c.key.x) >= kMaxKeyMagnitude || std::abs(c.key.y) >= kMaxKeyMagnitude ||
        std::abs(c.key.z) >= kMaxKeyMagnitude || !valid_state_value(static_cast<int>(c.state))) {
      last_error_ = "delta " + std::to_string(d.seq) + ": voxel key or state out of range";
      return false;
    }
  }
  return true;
}

void MapMirror::apply_changes(const MapDelta& d) {
  last_applied_.seq = d.seq;
  last_applied_.utime = d.utime;
  last_applied_.resolution = d.resolution;
  last_applied_.changes.resize(d.changes.size());
  for (size_t i = 0; i < d.changes.size(); ++i) {
    const VoxelChange& c = d.changes[i];
    last_applied_.changes[i] = {c.key, c.state, grid_.state(c.key)};
    grid_.set_state(c.key, c.state);
  }
  seq_ = d.seq;
  last_delta_seq_ = d.seq;
  ++counters_.deltas_applied;
}

MapMirror::DeltaResult MapMirror::apply(const MapDelta& d) {
  if (!valid(d)) {
    ++counters_.deltas_rejected;
    return DeltaResult::kRejected;
  }
  if (!needs_snapshot_ && d.seq == seq_ + 1) {
    apply_changes(d);
    return DeltaResult::kApplied;
  }
  if (!needs_snapshot_ && d.seq > last_delta_seq_ && d.seq <= seq_) {
    // Snapshots and updates are two channels, each in its publisher's order but not against each
    // other: on a lossy or jittery bus the snapshot of map s can come before the updates after the
    // last one applied, up to s, which it holds. Not a gap. (An update at or below the last one
    // applied is a mapper that began again: a gap.)
    ++counters_.deltas_ignored;
    return DeltaResult::kIgnored;
  }
  if (!needs_snapshot_) {
    needs_snapshot_ = true;
    ++counters_.gaps;
  }
  // A later copy of the same seq wins: after a mapper restart it is the one that counts.
  buffer_[d.seq] = d;
  while (buffer_.size() > max_buffered_) buffer_.erase(buffer_.begin());
  ++counters_.deltas_buffered;
  return DeltaResult::kBuffered;
}

MapMirror::SnapshotResult MapMirror::apply(const MapSnapshot& s) {
  if (!needs_snapshot_ && s.seq <= seq_) {
    ++counters_.snapshots_ignored;
    return SnapshotResult::kIgnored;
  }
  try {
    decode_snapshot(s, grid_);
  } catch (const SnapshotError& e) {
    last_error_ = e.what();
    ++counters_.snapshots_rejected;
    return SnapshotResult::kRejected;
  }
  seq_ = s.seq;
  needs_snapshot_ = false;
  ++counters_.snapshots_applied;
  drain_buffer();
  return SnapshotResult::kApplied;
}

void MapMirror::drain_buffer() {
  buffer_.erase(buffer_.begin(), buffer_.upper_bound(seq_));
  while (!buffer_.empty() && buffer_.begin()->first == seq_ + 1) {
    apply_changes(buffer_.begin()->second);
    buffer_.erase(buffer_.begin());
  }
  // Deltas beyond a further gap: still out of sequence.
  if (!buffer_.empty()) {
    needs_snapshot_ = true;
    ++counters_.gaps;
  }
}

}  // namespace semx::map
