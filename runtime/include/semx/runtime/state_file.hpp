// Files a process keeps its state in, so that when the launcher restarts it after a crash it
// resumes instead of starting over (docs/launch.md, "When a process dies"). Every record is
// [u32 kind][u32 size][u32 crc32 of the payload][payload], so a foreign, torn or stale file is
// refused, never half-read. Two shapes:
//   StateSlot     one record, rewritten in place by one pwrite: state small enough to write whole
//                 every tick (the simulator's). A process killed at any instant leaves the
//                 previous or the new record, as the kernel finishes a write it started.
//   StateJournal  records appended one write each and read back in order up to the first
//                 incomplete one: state that grows (the evaluator's series, the mapper's deltas
//                 since its checkpoint), so each save costs what is new, not everything so far.
// Nothing is fsync'ed: they survive a process's death, not the machine's.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace semx::runtime {

class StateFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class StateSlot {
 public:
  // Creates or truncates `path` (its directory must exist); throws StateFileError.
  StateSlot(std::string path, uint32_t kind);
  ~StateSlot();
  StateSlot(const StateSlot&) = delete;
  StateSlot& operator=(const StateSlot&) = delete;
  // Throws StateFileError when the write fails.
  void write(const std::vector<uint8_t>& payload);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  uint32_t kind_;
  int fd_ = -1;
  std::vector<uint8_t> buffer_;
};

// The slot's payload; nullopt when there is no file (or it is empty). Throws StateFileError
// naming the file when it holds no valid record of `kind`.
std::optional<std::vector<uint8_t>> read_state_slot(const std::string& path, uint32_t kind);

class StateJournal {
 public:
  // Opens `path` for appending (truncate: empties it first); throws StateFileError.
  StateJournal(std::string path, uint32_t kind, bool truncate);
  ~StateJournal();
  StateJournal(const StateJournal&) = delete;
  StateJournal& operator=(const StateJournal&) = delete;
  void append(const std::vector<uint8_t>& payload);
  void append(const uint8_t* payload, std::size_t size);
  // Empties the file (what it held is saved elsewhere now, e.g. in a checkpoint).
  void clear();
  // Cuts the file to `bytes` (read_state_journal's valid_bytes: drops a torn last record).
  void truncate(uint64_t bytes);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  uint32_t kind_;
  int fd_ = -1;
  std::vector<uint8_t> buffer_;
};

// The journal's records in order, up to the first that is incomplete or corrupt (what a process
// killed while appending leaves); `valid_bytes` gets the length they span. No file: none.
// Throws StateFileError when the first record is not of `kind` (another file).
std::vector<std::vector<uint8_t>> read_state_journal(const std::string& path, uint32_t kind,
                                                     uint64_t* valid_bytes = nullptr);

// Four characters as a record kind, e.g. state_kind("SIM1").
constexpr uint32_t state_kind(const char (&c)[5]) {
  return static_cast<uint32_t>(static_cast<uint8_t>(c[0])) | static_cast<uint32_t>(static_cast<uint8_t>(c[1])) << 8 |
         static_cast<uint32_t>(static_cast<uint8_t>(c[2])) << 16 |
         static_cast<uint32_t>(static_cast<uint8_t>(c[3])) << 24;
}

}  // namespace semx::runtime
