// The three states every consumer of the map reasons about. The numeric values are part of the
// message contract (map_update_t.state) and of the snapshot and checkpoint formats.
#pragma once

#include <cstdint>

namespace semx::map {

enum class VoxelState : uint8_t {
  kUnknown = 0,   // never observed
  kFree = 1,      // observed, occupancy log-odds below the threshold
  kOccupied = 2,  // observed, occupancy log-odds at or above the threshold
};

inline const char* to_string(VoxelState s) {
  switch (s) {
    case VoxelState::kUnknown:
      return "unknown";
    case VoxelState::kFree:
      return "free";
    case VoxelState::kOccupied:
      return "occupied";
  }
  return "invalid";
}

inline bool valid_state_value(int v) { return v >= 0 && v <= 2; }

}  // namespace semx::map
