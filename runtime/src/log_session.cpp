#include "semx/runtime/log_session.hpp"

#include <lcm/lcm-cpp.hpp>
#include <semx/sim_event_t.hpp>

#include <filesystem>

#include "semx/runtime/channels.hpp"

namespace semx::runtime {

LogSession::LogSession(const std::string& path, const LogLayout& layout, const std::optional<AuthKey>& key) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw LogError(path + ": lcm::LogFile cannot open it");
  bool chosen = false;
  // Only the events the scan found complete: LogFile's reader is not safe past them.
  for (int64_t i = 0; i < layout.events; ++i) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    const auto* data = static_cast<const uint8_t*>(e->data);
    const auto size = static_cast<std::size_t>(e->datalen);
    const auto trailer = read_trailer(data, size);
    if (!trailer) continue;
    signed_log_ = true;
    if (key || chosen) break;
    if (e->channel != channels::SIM_EVENT) continue;
    semx::sim_event_t ev{};
    try {
      const int n = static_cast<int>(size - kAuthTrailerBytes);
      if (ev.decode(data, 0, n) != n || ev.type != semx::sim_event_t::EPISODE_START) continue;
    } catch (const std::exception&) {
      continue;
    }
    session_ = trailer->session;
    chosen = true;
  }
  if (key) {
    verifier_ = std::make_unique<MessageVerifier>(*key);
    session_ = key->session();
  } else if (signed_log_ && !chosen) {
    throw LogError(path + ": the log holds no SIM_EVENT EPISODE_START, so which set's messages to read is "
                          "unknown; give the run's key (--auth-key RUN/session.key)");
  }
}

LogSession::~LogSession() = default;
LogSession::LogSession(LogSession&&) noexcept = default;
LogSession& LogSession::operator=(LogSession&&) noexcept = default;

std::optional<std::size_t> LogSession::payload(const std::string& channel, const uint8_t* data, std::size_t size) {
  if (!signed_log_) return size;
  if (verifier_) {
    const AuthVerdict v = verifier_->verify(channel, data, size);
    if (v == AuthVerdict::kOk) return size - kAuthTrailerBytes;
    ++(v == AuthVerdict::kForeign ? foreign_ : refused_);
    return std::nullopt;
  }
  const auto trailer = read_trailer(data, size);
  if (!trailer) {
    ++refused_;
    return std::nullopt;
  }
  if (trailer->session != session_) {
    ++foreign_;
    return std::nullopt;
  }
  return size - kAuthTrailerBytes;
}

std::string LogSession::summary() const {
  if (foreign_ == 0 && refused_ == 0) return "";
  std::string s;
  if (foreign_ > 0) s += std::to_string(foreign_) + " events of another set on the same bus";
  if (refused_ > 0) {
    s += (s.empty() ? "" : ", ") + std::to_string(refused_) +
         (verifier_ ? " unsigned, forged or replayed events" : " unsigned events");
  }
  return s + " left out";
}

std::optional<AuthKey> key_beside(const std::string& log_path) {
  const auto file = std::filesystem::path(log_path).parent_path() / "session.key";
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return std::nullopt;
  return AuthKey::from_file(file.string());
}

}  // namespace semx::runtime
