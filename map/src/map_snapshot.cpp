#include "semx/map/map_snapshot.hpp"

#include <cmath>

#include "semx/map/byte_io.hpp"

namespace semx::map {

namespace {
constexpr uint32_t kVersion = 1;
constexpr size_t kRawHeader = 4 + 4 + 8 + 8 + 4;
constexpr size_t kPackedBlock = kBlockVolume / 4;
constexpr size_t kBlockRecord = 12 + kPackedBlock;
// A snapshot larger than this is corrupt, not a map (it would be ~4 billion known voxels).
constexpr uint64_t kMaxRaw = uint64_t{1} << 30;
}  // namespace

MapSnapshot encode_snapshot(const StateGrid& grid, int64_t seq, int64_t utime) {
  std::vector<VoxelKey> keys = grid.sorted_block_keys();
  std::vector<uint8_t> raw;
  raw.reserve(kRawHeader + keys.size() * kBlockRecord);
  detail::ByteWriter w(raw);
  w.bytes("SXS1", 4);
  w.u32(kVersion);
  w.f64(grid.resolution());
  w.i64(seq);
  const size_t count_at = raw.size();
  w.u32(0);
  uint32_t count = 0;
  uint8_t packed[kPackedBlock];
  for (const VoxelKey& bk : keys) {
    const VoxelBlock* b = grid.find_block(bk);
    if (b->known == 0) continue;
    for (size_t j = 0; j < kPackedBlock; ++j) {
      packed[j] = static_cast<uint8_t>(static_cast<uint8_t>(b->state[4 * j]) |
                                       (static_cast<uint8_t>(b->state[4 * j + 1]) << 2) |
                                       (static_cast<uint8_t>(b->state[4 * j + 2]) << 4) |
                                       (static_cast<uint8_t>(b->state[4 * j + 3]) << 6));
    }
    w.i32(bk.x);
    w.i32(bk.y);
    w.i32(bk.z);
    w.bytes(packed, kPackedBlock);
    ++count;
  }
  for (int i = 0; i < 4; ++i) raw[count_at + i] = static_cast<uint8_t>(count >> (8 * i));

  MapSnapshot s;
  s.seq = seq;
  s.utime = utime;
  s.resolution = grid.resolution();
  s.encoding = kSnapshotBlocksZlib;
  // Level 1: the packed states compress ~10x even at the fastest level, and the mapper encodes
  // snapshots on its frame thread.
  const std::vector<uint8_t> z = detail::zlib_compress(raw, 1);
  detail::ByteWriter dw(s.data);
  dw.u64(raw.size());
  dw.bytes(z.data(), z.size());
  return s;
}

void decode_snapshot(const MapSnapshot& s, StateGrid& out) {
  if (s.encoding != kSnapshotBlocksZlib) {
    throw SnapshotError("snapshot: unknown encoding " + std::to_string(s.encoding));
  }
  if (!(std::abs(s.resolution - out.resolution()) <= 1e-9 * out.resolution())) {
    throw SnapshotError("snapshot: resolution " + std::to_string(s.resolution) + " m, map has " +
                        std::to_string(out.resolution()) + " m");
  }
  if (s.data.size() < 8) throw SnapshotError("snapshot: data too short");
  detail::ByteReader head(s.data.data(), s.data.size());
  const uint64_t raw_size = head.u64();
  if (raw_size < kRawHeader || raw_size > kMaxRaw || (raw_size - kRawHeader) % kBlockRecord != 0) {
    throw SnapshotError("snapshot: implausible size " + std::to_string(raw_size));
  }
  std::vector<uint8_t> raw;
  if (!detail::zlib_decompress(s.data.data() + 8, s.data.size() - 8, raw_size, raw)) {
    throw SnapshotError("snapshot: corrupt compressed data");
  }
  detail::ByteReader r(raw.data(), raw.size());
  const uint8_t* magic = r.take(4);
  if (std::string(reinterpret_cast<const char*>(magic), 4) != "SXS1")
    throw SnapshotError("snapshot: bad magic");
  if (r.u32() != kVersion) throw SnapshotError("snapshot: unsupported version");
  const double res = r.f64();
  const int64_t seq = r.i64();
  const uint32_t count = r.u32();
  if (res != s.resolution || seq != s.seq) throw SnapshotError("snapshot: header disagrees with its message");
  if (static_cast<uint64_t>(count) * kBlockRecord != raw_size - kRawHeader) {
    throw SnapshotError("snapshot: block count does not match its size");
  }
  StateGrid fresh(out.resolution(), out.with_log_odds());
  constexpr int32_t kMaxBlock = kMaxKeyMagnitude >> kBlockBits;
  for (uint32_t n = 0; n < count; ++n) {
    const VoxelKey bk{r.i32(), r.i32(), r.i32()};
    if (std::abs(bk.x) >= kMaxBlock || std::abs(bk.y) >= kMaxBlock || std::abs(bk.z) >= kMaxBlock) {
      throw SnapshotError("snapshot: block key out of range");
    }
    if (fresh.find_block(bk)) throw SnapshotError("snapshot: duplicate block");
    const uint8_t* packed = r.take(kPackedBlock);
    VoxelBlock& b = fresh.get_or_create_block(bk);
    for (int i = 0; i < kBlockVolume; ++i) {
      const int v = (packed[i >> 2] >> (2 * (i & 3))) & 3;
      if (!valid_state_value(v)) throw SnapshotError("snapshot: invalid voxel state");
      const auto st = static_cast<VoxelState>(v);
      if (st == VoxelState::kUnknown) continue;
      b.state[i] = st;
      fresh.note_transition(b, voxel_of(bk, i), VoxelState::kUnknown, st);
    }
  }
  out = std::move(fresh);
}

}  // namespace semx::map
