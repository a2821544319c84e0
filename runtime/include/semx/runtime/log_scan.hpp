// The layout of an lcm-logger log from its event headers alone. LCM 1.3.1's reader asserts or
// allocates blindly on a corrupt header, so every tool that reads a log (semx-map-replay,
// semx-eval) scans it first and refuses a file that is not a log, or is corrupt in the middle,
// with the byte offset of the problem; a log whose last event was cut short (the logger killed
// while writing) is read up to that event.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace semx::runtime {

class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LogLayout {
  int64_t events = 0;  // complete events
  uint64_t file_bytes = 0;
  bool truncated = false;     // the file ends inside an event
  uint64_t truncated_at = 0;  // byte offset of that event
};

// Throws LogError naming the file: missing or unreadable, empty, not an LCM log, or a corrupt
// event header (with its byte offset and event number).
LogLayout scan_log(const std::string& path);

}  // namespace semx::runtime
