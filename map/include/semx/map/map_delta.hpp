// What changed in the map after one frame: the voxels whose state changed, with their new state,
// numbered so a client can tell when it missed one (MAP_UPDATE).
//
// Sequence semantics: the map at sequence s is the empty map after the first s deltas. Every
// accepted frame yields exactly one delta (possibly with no changes) and increments the
// sequence, so a client that applied delta s can apply s + 1 and nothing else. A restored
// checkpoint continues at checkpoint sequence + kRestoreSequenceJump (see Mapper).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "semx/map/voxel_key.hpp"
#include "semx/map/voxel_state.hpp"

namespace semx::map {

struct VoxelChange {
  VoxelChange() = default;
  VoxelChange(const VoxelKey& k, VoxelState s, std::optional<VoxelState> before = std::nullopt)
      : key(k), state(s), previous(before) {}

  VoxelKey key;
  VoxelState state = VoxelState::kUnknown;  // the new state
  // The state before, where whoever applied the change knew it (MapMirror::last_applied(); not
  // in MAP_UPDATE): lets a reader skip changes that cannot concern it, e.g. unknown -> free for
  // a check that counts only occupied voxels.
  std::optional<VoxelState> previous;
};

struct MapDelta {
  int64_t seq = 0;
  int64_t utime = 0;  // of the frame that produced it
  double resolution = 0.0;
  std::vector<VoxelChange> changes;  // each key at most once

  bool empty() const { return changes.empty(); }
};

}  // namespace semx::map
