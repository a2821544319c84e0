// Which events of an LCM log belong to the recorded run. A log holds every message's trailer
// (message_auth.hpp); a stock lcm-logger recording may also hold another set's messages, sent on
// the same bus at the same time. Log readers (semx-eval, semx-map-replay) read only the run's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "semx/runtime/log_scan.hpp"
#include "semx/runtime/message_auth.hpp"

namespace semx::runtime {

class LogSession {
 public:
  // With the run's key (its run folder's session.key), every event's tag is checked. Without,
  // the run is the session of the first SIM_EVENT EPISODE_START (scanned here; nothing can be
  // verified). A log without any trailer (written before messages were signed, or by a test)
  // is read whole.
  LogSession(const std::string& path, const LogLayout& layout, const std::optional<AuthKey>& key);
  ~LogSession();
  LogSession(LogSession&&) noexcept;
  LogSession& operator=(LogSession&&) noexcept;

  // The number of bytes of `data` LCM's decoders should read, or nullopt when the event is not
  // the run's (counted).
  std::optional<std::size_t> payload(const std::string& channel, const uint8_t* data, std::size_t size);

  bool signed_log() const { return signed_log_; }
  bool verified() const { return verifier_ != nullptr; }
  uint64_t session() const { return session_; }
  int64_t foreign() const { return foreign_; }  // another set's events
  int64_t refused() const { return refused_; }  // unsigned in a signed log, forged or replayed
  // One line for a report, empty when nothing was left out.
  std::string summary() const;

 private:
  std::unique_ptr<MessageVerifier> verifier_;
  bool signed_log_ = false;
  uint64_t session_ = 0;
  int64_t foreign_ = 0;
  int64_t refused_ = 0;
};

// The key file beside a log (RUN/session.key for RUN/run.lcmlog), if there is one.
std::optional<AuthKey> key_beside(const std::string& log_path);

}  // namespace semx::runtime
