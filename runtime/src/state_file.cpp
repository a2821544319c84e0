#include "semx/runtime/state_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

namespace semx::runtime {

namespace {

constexpr std::size_t kHeader = 12;
// A record larger than this is not one of ours (a size field read from garbage).
constexpr uint32_t kMaxRecord = 1u << 30;

uint32_t crc_of(const uint8_t* data, std::size_t size) {
  return static_cast<uint32_t>(crc32(crc32(0L, Z_NULL, 0), data, static_cast<uInt>(size)));
}

void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(p[i]) << (8 * i);
  return v;
}

void frame(std::vector<uint8_t>& out, uint32_t kind, const uint8_t* payload, std::size_t size) {
  if (size > kMaxRecord) throw StateFileError("state record of " + std::to_string(size) + " bytes is too large");
  out.resize(kHeader + size);
  put_u32(out.data(), kind);
  put_u32(out.data() + 4, static_cast<uint32_t>(size));
  put_u32(out.data() + 8, crc_of(payload, size));
  if (size > 0) std::memcpy(out.data() + kHeader, payload, size);
}

int open_file(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC, 0644);
  if (fd < 0) throw StateFileError(path + ": " + std::strerror(errno));
  return fd;
}

void write_all(int fd, const std::vector<uint8_t>& bytes, const std::string& path, bool at_start) {
  // One call for the whole record, so a process killed meanwhile leaves all of it or none.
  const ssize_t n = at_start ? ::pwrite(fd, bytes.data(), bytes.size(), 0)
                             : ::write(fd, bytes.data(), bytes.size());
  if (n != static_cast<ssize_t>(bytes.size())) {
    throw StateFileError(path + ": write failed: " + (n < 0 ? std::strerror(errno) : "short write"));
  }
}

std::optional<std::vector<uint8_t>> read_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

StateSlot::StateSlot(std::string path, uint32_t kind)
    : path_(std::move(path)), kind_(kind), fd_(open_file(path_, O_WRONLY | O_CREAT | O_TRUNC)) {}

StateSlot::~StateSlot() {
  if (fd_ >= 0) ::close(fd_);
}

void StateSlot::write(const std::vector<uint8_t>& payload) {
  frame(buffer_, kind_, payload.data(), payload.size());
  write_all(fd_, buffer_, path_, true);
}

std::optional<std::vector<uint8_t>> read_state_slot(const std::string& path, uint32_t kind) {
  const auto bytes = read_whole(path);
  if (!bytes || bytes->empty()) return std::nullopt;
  if (bytes->size() < kHeader) throw StateFileError(path + ": truncated state record");
  if (get_u32(bytes->data()) != kind) throw StateFileError(path + ": not a state file of this kind");
  const uint32_t size = get_u32(bytes->data() + 4);
  if (size > bytes->size() - kHeader) throw StateFileError(path + ": truncated state record");
  const uint8_t* payload = bytes->data() + kHeader;
  if (crc_of(payload, size) != get_u32(bytes->data() + 8)) throw StateFileError(path + ": checksum mismatch");
  return std::vector<uint8_t>(payload, payload + size);
}

StateJournal::StateJournal(std::string path, uint32_t kind, bool truncate)
    : path_(std::move(path)),
      kind_(kind),
      fd_(open_file(path_, O_WRONLY | O_CREAT | O_APPEND | (truncate ? O_TRUNC : 0))) {}

StateJournal::~StateJournal() {
  if (fd_ >= 0) ::close(fd_);
}

void StateJournal::append(const std::vector<uint8_t>& payload) { append(payload.data(), payload.size()); }

void StateJournal::append(const uint8_t* payload, std::size_t size) {
  frame(buffer_, kind_, payload, size);
  write_all(fd_, buffer_, path_, false);
}

void StateJournal::clear() { truncate(0); }

void StateJournal::truncate(uint64_t bytes) {
  if (::ftruncate(fd_, static_cast<off_t>(bytes)) != 0)
    throw StateFileError(path_ + ": cannot truncate: " + std::strerror(errno));
}

std::vector<std::vector<uint8_t>> read_state_journal(const std::string& path, uint32_t kind,
                                                     uint64_t* valid_bytes) {
  std::vector<std::vector<uint8_t>> records;
  if (valid_bytes) *valid_bytes = 0;
  const auto bytes = read_whole(path);
  if (!bytes) return records;
  std::size_t at = 0;
  while (bytes->size() - at >= kHeader) {
    const uint8_t* h = bytes->data() + at;
    if (get_u32(h) != kind) {
      if (at == 0) throw StateFileError(path + ": not a state journal of this kind");
      break;
    }
    const uint32_t size = get_u32(h + 4);
    if (size > bytes->size() - at - kHeader) break;
    if (crc_of(h + kHeader, size) != get_u32(h + 8)) break;
    records.emplace_back(h + kHeader, h + kHeader + size);
    at += kHeader + size;
  }
  if (valid_bytes) *valid_bytes = at;
  return records;
}

}  // namespace semx::runtime
