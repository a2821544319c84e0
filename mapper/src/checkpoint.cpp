#include "semx/mapper/checkpoint.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "semx/map/byte_io.hpp"

namespace semx::mapper {

namespace {

constexpr char kMagic[8] = {'S', 'E', 'M', 'X', 'M', 'A', 'P', '\0'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderSize = 96;
constexpr size_t kBlockRecord = 12 + map::kBlockVolume * sizeof(float);

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MapIoError("map checkpoint '" + path + "': " + what);
}

struct Header {
  CheckpointInfo info;
  float l[5] = {};
  uint64_t raw_size = 0;
  uint64_t compressed_size = 0;
  uint32_t payload_crc = 0;
};

Header parse_header(const std::string& path, const std::vector<uint8_t>& file) {
  if (file.size() < kHeaderSize) {
    fail(path, "truncated: " + std::to_string(file.size()) + " bytes, shorter than the " +
                   std::to_string(kHeaderSize) + "-byte header");
  }
  if (std::memcmp(file.data(), kMagic, 8) != 0) fail(path, "not a semx map checkpoint (bad magic)");
  map::detail::ByteReader r(file.data() + 8, kHeaderSize - 8);
  Header h;
  h.info.version = r.u32();
  if (h.info.version != kVersion) {
    fail(path, "unsupported format version " + std::to_string(h.info.version) + " (this build reads " +
                   std::to_string(kVersion) + ")");
  }
  const uint32_t header_size = r.u32();
  h.info.resolution = r.f64();
  for (float& v : h.l) v = r.f32();
  r.u32();
  h.info.seq = r.i64();
  h.info.utime = r.i64();
  h.info.blocks = r.u64();
  h.raw_size = r.u64();
  h.compressed_size = r.u64();
  h.payload_crc = r.u32();
  const uint32_t header_crc = r.u32();
  if (header_crc != map::detail::crc32_of(file.data(), kHeaderSize - 4))
    fail(path, "header checksum mismatch (corrupt file)");
  if (header_size != kHeaderSize) fail(path, "unexpected header size " + std::to_string(header_size));
  h.info.file_bytes = file.size();
  return h;
}

std::vector<uint8_t> read_file(const std::string& path, size_t limit) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  std::vector<uint8_t> data;
  char buf[1 << 16];
  while (in && data.size() < limit) {
    in.read(buf, sizeof(buf));
    data.insert(data.end(), buf, buf + in.gcount());
  }
  if (in.bad()) fail(path, "read error");
  return data;
}

}  // namespace

CheckpointInfo save_checkpoint(const OccupancyMap& map, int64_t seq, int64_t utime, const std::string& path) {
  const map::StateGrid& grid = map.grid();
  std::vector<uint8_t> raw;
  map::detail::ByteWriter w(raw);
  uint64_t blocks = 0;
  float values[map::kBlockVolume];
  for (const map::VoxelKey& bk : grid.sorted_block_keys()) {
    const map::VoxelBlock* b = grid.find_block(bk);
    if (b->known == 0) continue;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      values[i] =
          b->state[i] == map::VoxelState::kUnknown ? std::numeric_limits<float>::quiet_NaN() : b->log_odds[i];
    }
    w.i32(bk.x);
    w.i32(bk.y);
    w.i32(bk.z);
    for (float v : values) w.f32(v);
    ++blocks;
  }
  const std::vector<uint8_t> payload = map::detail::zlib_compress(raw, 1);

  std::vector<uint8_t> header;
  map::detail::ByteWriter h(header);
  h.bytes(kMagic, 8);
  h.u32(kVersion);
  h.u32(kHeaderSize);
  h.f64(map.resolution());
  h.f32(map.hit_log_odds());
  h.f32(map.miss_log_odds());
  h.f32(map.min_log_odds());
  h.f32(map.max_log_odds());
  h.f32(map.threshold_log_odds());
  h.u32(0);
  h.i64(seq);
  h.i64(utime);
  h.u64(blocks);
  h.u64(raw.size());
  h.u64(payload.size());
  h.u32(map::detail::crc32_of(payload.data(), payload.size()));
  h.u32(map::detail::crc32_of(header.data(), header.size()));

  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) fail(path, "cannot write '" + tmp + "': " + std::strerror(errno));
  const bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size() &&
                  std::fwrite(payload.data(), 1, payload.size(), f) == payload.size() && std::fflush(f) == 0;
  const int err = errno;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    fail(path, "cannot write '" + tmp + "': " + std::strerror(err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    fail(path, std::string("cannot rename the temporary file into place: ") + std::strerror(e));
  }
  CheckpointInfo info;
  info.version = kVersion;
  info.resolution = map.resolution();
  info.seq = seq;
  info.utime = utime;
  info.blocks = blocks;
  info.file_bytes = header.size() + payload.size();
  return info;
}

CheckpointInfo read_checkpoint_info(const std::string& path) {
  return parse_header(path, read_file(path, kHeaderSize)).info;
}

CheckpointInfo load_checkpoint(const std::string& path, OccupancyMap& map) {
  const std::vector<uint8_t> file = read_file(path, std::numeric_limits<size_t>::max());
  const Header h = parse_header(path, file);
  const uint64_t expected = kHeaderSize + h.compressed_size;
  if (h.compressed_size > file.size() || file.size() < expected) {
    fail(path,
         "truncated: " + std::to_string(file.size()) + " bytes, the header says " + std::to_string(expected));
  }
  if (file.size() > expected) {
    fail(path, std::to_string(file.size() - expected) + " unexpected bytes after the payload");
  }
  const uint8_t* payload = file.data() + kHeaderSize;
  if (map::detail::crc32_of(payload, h.compressed_size) != h.payload_crc) {
    fail(path, "payload checksum mismatch (corrupt file)");
  }
  if (h.info.blocks > (uint64_t{1} << 24) || h.raw_size != h.info.blocks * kBlockRecord) {
    fail(path, "payload size " + std::to_string(h.raw_size) + " does not match " +
                   std::to_string(h.info.blocks) + " blocks");
  }
  if (!(std::abs(h.info.resolution - map.resolution()) <= 1e-9 * map.resolution())) {
    fail(path, "resolution " + std::to_string(h.info.resolution) + " m, the map is configured for " +
                   std::to_string(map.resolution()) + " m");
  }
  std::vector<uint8_t> raw;
  if (!map::detail::zlib_decompress(payload, h.compressed_size, h.raw_size, raw))
    fail(path, "corrupt compressed payload");

  OccupancyMap fresh(map.params());
  map::detail::ByteReader r(raw.data(), raw.size());
  constexpr int32_t kMaxBlock = map::kMaxKeyMagnitude >> map::kBlockBits;
  float values[map::kBlockVolume];
  for (uint64_t n = 0; n < h.info.blocks; ++n) {
    const map::VoxelKey bk{r.i32(), r.i32(), r.i32()};
    if (std::abs(bk.x) >= kMaxBlock || std::abs(bk.y) >= kMaxBlock || std::abs(bk.z) >= kMaxBlock) {
      fail(path, "block key out of range");
    }
    if (fresh.grid().find_block(bk)) fail(path, "duplicate block");
    for (float& v : values) v = r.f32();
    fresh.set_block_log_odds(bk, values);
  }
  map = std::move(fresh);
  return h.info;
}

}  // namespace semx::mapper
