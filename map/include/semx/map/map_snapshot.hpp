// The whole map's states in one compressed message (MAP_SNAPSHOT), for late joiners and for
// clients that missed a delta.
//
// Encoding kSnapshotBlocksZlib (= 1), little-endian:
//   data = u64 raw_size, then zlib(raw)
//   raw  = "SXS1", u32 version (1), f64 resolution, i64 seq, u32 block_count,
//          block_count x { i32 bx, by, bz; 1024 bytes: 4096 2-bit states }
// Voxel (x, y, z) of block (bx, by, bz) has key (16 bx + x, ...) and local index
// i = x + 16 y + 256 z; its state is bits 2(i mod 4)..2(i mod 4)+1 of byte i / 4.
// Blocks without known voxels are omitted; blocks are in ascending (z, y, x) order, so the same
// map always encodes to the same bytes.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "semx/map/state_grid.hpp"

namespace semx::map {

inline constexpr int8_t kSnapshotBlocksZlib = 1;

struct MapSnapshot {
  int64_t seq = 0;  // the last delta included
  int64_t utime = 0;
  double resolution = 0.0;
  int8_t encoding = kSnapshotBlocksZlib;
  std::vector<uint8_t> data;
};

class SnapshotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

MapSnapshot encode_snapshot(const StateGrid& grid, int64_t seq, int64_t utime = 0);
// Replaces the content of `out` (whose resolution must match) with the snapshot's. Throws
// SnapshotError on any malformed input and then leaves `out` unchanged.
void decode_snapshot(const MapSnapshot& snapshot, StateGrid& out);

}  // namespace semx::map
