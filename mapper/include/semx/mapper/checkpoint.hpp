// Checkpoint files: the full log-odds map, so a restarted mapper continues where it stopped.
//
// Format (version 1, little-endian): a 96-byte header
//   0  char[8] "SEMXMAP\0"      40 f32 log-odds threshold
//   8  u32 format version (1)  44 u32 reserved (0)
//   12 u32 header size (96)    48 i64 map seq          56 i64 utime
//   16 f64 resolution          64 u64 block count      72 u64 raw payload size
//   24 f32 l_hit, 28 l_miss,   80 u64 compressed payload size
//   32 l_min, 36 l_max         88 u32 CRC-32 of the payload   92 u32 CRC-32 of bytes 0..91
// then the payload: zlib(block_count x { i32 bx, by, bz; 4096 f32 log-odds, NaN = unknown }),
// blocks in ascending (z, y, x) order. Files are written to "<path>.tmp" and renamed, so a crash
// while writing leaves the previous checkpoint intact.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "semx/mapper/occupancy_map.hpp"

namespace semx::mapper {

// Every I/O failure of the mapper's files; the message names the file.
class MapIoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CheckpointInfo {
  uint32_t version = 0;
  double resolution = 0.0;
  int64_t seq = 0;
  int64_t utime = 0;
  uint64_t blocks = 0;
  uint64_t file_bytes = 0;
};

CheckpointInfo save_checkpoint(const OccupancyMap& map, int64_t seq, int64_t utime, const std::string& path);
// Replaces `map`'s content with the file's. The resolution must equal the map's; log-odds are
// re-clamped and re-classified with the map's own parameters. On any error throws MapIoError
// naming the file and what is wrong (missing, truncated, bad magic or version, checksum
// mismatch, resolution mismatch, corrupt payload), and leaves `map` unchanged.
CheckpointInfo load_checkpoint(const std::string& path, OccupancyMap& map);
// Header only (validated), e.g. to decide whether to load.
CheckpointInfo read_checkpoint_info(const std::string& path);

}  // namespace semx::mapper
