#include "semx/runtime/log_scan.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace semx::runtime {

namespace fs = std::filesystem;

namespace {

// lcm-logger's event header: u32 sync, i64 event number, i64 timestamp, i32 channel length,
// i32 data length, all big-endian; then the channel name and the data.
constexpr uint32_t kSync = 0xEDA1DA01u;
constexpr size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
// LCM's reader asserts channel names shorter than 1000 bytes.
constexpr int32_t kMaxChannelBytes = 999;

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

}  // namespace

LogLayout scan_log(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw LogError(path + ": no such file");
  if (fs::is_directory(path, ec)) throw LogError(path + ": is a directory, not an LCM log");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw LogError(path + ": cannot open (" + std::strerror(errno) + ")");
  LogLayout l;
  l.file_bytes = fs::file_size(path, ec);
  if (ec) throw LogError(path + ": cannot read its size (" + ec.message() + ")");
  if (l.file_bytes == 0) throw LogError(path + ": empty file, not an LCM log");
  uint64_t pos = 0;
  uint8_t h[kHeaderBytes];
  while (pos < l.file_bytes) {
    if (l.file_bytes - pos < kHeaderBytes) {
      l.truncated = true;
      l.truncated_at = pos;
      break;
    }
    in.seekg(static_cast<std::streamoff>(pos));
    if (!in.read(reinterpret_cast<char*>(h), kHeaderBytes)) {
      throw LogError(path + ": read error at byte " + std::to_string(pos));
    }
    const std::string where = " at byte " + std::to_string(pos) + " (event " + std::to_string(l.events) + ")";
    if (be32(h) != kSync) {
      throw LogError(pos == 0 ? path + ": not an LCM log (no event sync word at byte 0)"
                              : path + ": corrupt log: no event sync word" + where);
    }
    const auto channel_len = static_cast<int32_t>(be32(h + 20));
    const auto data_len = static_cast<int32_t>(be32(h + 24));
    if (channel_len <= 0 || channel_len > kMaxChannelBytes) {
      throw LogError(path + ": corrupt log: channel name length " + std::to_string(channel_len) + where);
    }
    if (data_len < 0) throw LogError(path + ": corrupt log: negative data length" + where);
    const uint64_t end =
        pos + kHeaderBytes + static_cast<uint64_t>(channel_len) + static_cast<uint64_t>(data_len);
    if (end > l.file_bytes) {
      l.truncated = true;
      l.truncated_at = pos;
      break;
    }
    pos = end;
    ++l.events;
  }
  if (l.events == 0) throw LogError(path + ": no complete LCM event (the file ends inside the first one)");
  return l;
}

}  // namespace semx::runtime
