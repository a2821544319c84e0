#include "semx/tools/status_board.hpp"

#include <cstdio>

namespace semx::tools {

namespace {
const char* state_name(int8_t s) {
  static const char* names[] = {"starting", "running", "degraded", "done", "stopping", "failed"};
  return s >= 0 && s < 6 ? names[s] : "?";
}
}  // namespace

void StatusBoard::on_status(const semx::node_status_t& s, double wall_s) {
  NodeRow& row = nodes_[s.node];
  if (row.prev_seen_s >= 0 && row.status.pid == s.pid && wall_s > row.prev_seen_s + 0.2) {
    row.cpu_percent = 100.0 * (s.cpu_s - row.prev_cpu_s) / (wall_s - row.prev_seen_s);
  }
  if (row.prev_seen_s < 0 || wall_s > row.prev_seen_s + 0.2 || row.status.pid != s.pid) {
    row.prev_cpu_s = s.cpu_s;
    row.prev_seen_s = wall_s;
  }
  row.status = s;
  row.last_seen_s = wall_s;
}

void StatusBoard::on_message(const std::string& channel, std::size_t bytes, bool malformed) {
  ChannelRow& row = channels_[channel];
  ++row.messages;
  row.bytes += static_cast<int64_t>(bytes);
  if (malformed) ++row.malformed;
}

void StatusBoard::update_rates(double wall_s) {
  const double dt = window_start_s_ < 0 ? 0 : wall_s - window_start_s_;
  for (auto& [name, row] : channels_) {
    if (dt > 0) {
      row.hz = static_cast<double>(row.messages - row.window_messages) / dt;
      row.kbps = static_cast<double>(row.bytes - row.window_bytes) / dt / 1024.0;
    }
    row.window_messages = row.messages;
    row.window_bytes = row.bytes;
  }
  window_start_s_ = wall_s;
}

std::vector<std::string> StatusBoard::missing(const std::vector<std::string>& names) const {
  std::vector<std::string> out;
  for (const auto& n : names) {
    auto it = nodes_.find(n);
    if (it == nodes_.end() || it->second.status.state >= 4) out.push_back(n);
  }
  return out;
}

std::string StatusBoard::render_nodes(double wall_s) const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-16s %7s %3s %-9s %9s %9s %9s %6s %6s %6s %7s %5s  %s\n", "NODE", "PID",
                "RST", "STATE", "SIM_T[s]", "RECV", "SENT", "DROP", "BAD", "CPU%", "RSS[MB]", "AGE", "DETAIL");
  out += line;
  for (const auto& [name, row] : nodes_) {
    const auto& s = row.status;
    std::snprintf(line, sizeof line, "%-16s %7d %3d %-9s %9.2f %9lld %9lld %6lld %6lld %6.1f %7.1f %5.1f  %s\n",
                  name.c_str(), s.pid, s.restarts, state_name(s.state), static_cast<double>(s.utime) * 1e-6,
                  static_cast<long long>(s.received), static_cast<long long>(s.sent),
                  static_cast<long long>(s.dropped), static_cast<long long>(s.malformed), row.cpu_percent,
                  static_cast<double>(s.rss_kb) / 1024.0, wall_s - row.last_seen_s, s.detail.c_str());
    out += line;
  }
  return out;
}

std::string StatusBoard::render_channels() const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-20s %10s %8s %10s %8s\n", "CHANNEL", "MESSAGES", "HZ", "KB/S", "BAD");
  out += line;
  for (const auto& [name, row] : channels_) {
    std::snprintf(line, sizeof line, "%-20s %10lld %8.1f %10.1f %8lld\n", name.c_str(),
                  static_cast<long long>(row.messages), row.hz, row.kbps,
                  static_cast<long long>(row.malformed));
    out += line;
  }
  return out;
}

}  // namespace semx::tools
