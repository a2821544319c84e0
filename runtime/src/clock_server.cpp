#include "semx/runtime/clock_server.hpp"

#include <algorithm>
#include <stdexcept>

namespace semx::runtime {

ClockServer::ClockServer(ClockServerConfig config) : config_(std::move(config)) {
  if (config_.period_us <= 0) throw std::invalid_argument("clock period must be positive");
  if (config_.mode == ClockMode::kRealtime && !(config_.speed > 0)) {
    throw std::invalid_argument("realtime speed factor must be positive");
  }
}

bool ClockServer::satisfied(const std::string& node) const {
  const auto it = acks_.find(node);
  if (it == acks_.end()) return false;
  return it->second.tick >= tick_ || current_utime() < it->second.quiet_until;
}

bool ClockServer::tick_complete() const {
  if (config_.mode != ClockMode::kLockstep) return true;
  for (const auto& n : config_.lockstep_nodes) {
    if (!satisfied(n)) return false;
  }
  return true;
}

bool ClockServer::finished() const {
  return config_.max_ticks >= 0 && tick_ + 1 >= config_.max_ticks && tick_complete();
}

std::optional<ClockTick> ClockServer::poll(double wall_s, bool inputs_held) {
  if (start_wall_ < 0) start_wall_ = wall_s;
  if (finished()) return std::nullopt;
  bool due = false;
  if (tick_ < 0) {
    due = true;
  } else if (config_.mode == ClockMode::kRealtime) {
    due = wall_s >= start_wall_ + static_cast<double>(tick_ + 1) * config_.period_us * 1e-6 / config_.speed;
  } else {
    due = tick_complete() && inputs_held && (config_.max_speed <= 0 ||
                              wall_s >= start_wall_ + static_cast<double>(tick_ + 1) * config_.period_us *
                                                          1e-6 / config_.max_speed);
  }
  if (due) {
    ++tick_;
    tick_sent_at_ = last_send_ = wall_s;
    return ClockTick{tick_, current_utime(), false};
  }
  if (config_.mode == ClockMode::kLockstep && wall_s - last_send_ >= config_.resend_after_s) {
    last_send_ = wall_s;
    return ClockTick{tick_, current_utime(), true};
  }
  return std::nullopt;
}

void ClockServer::resume(int64_t tick, double wall_s) {
  tick_ = std::max<int64_t>(tick, 0);
  const double rate = config_.mode == ClockMode::kRealtime ? config_.speed : config_.max_speed;
  start_wall_ = wall_s - (rate > 0 ? static_cast<double>(tick_) * config_.period_us * 1e-6 / rate : 0.0);
  tick_sent_at_ = wall_s;
  last_send_ = wall_s - config_.resend_after_s;  // due for resending at once
  acks_.clear();
}

bool ClockServer::on_ack(const std::string& node, int64_t tick, int64_t quiet_until, double wall_s) {
  if (config_.mode != ClockMode::kLockstep || tick > tick_ || tick < 0) return false;
  NodeAcks& a = acks_[node];
  // Acks of one node come in order; an older one (a resent tick acked again) says nothing new.
  if (tick < a.tick) return false;
  const bool was_complete = tick_complete();
  a.tick = tick;
  const int64_t acked_utime = tick * config_.period_us;
  a.quiet_until = std::min(quiet_until, acked_utime + config_.max_slack_us);
  const bool completed = !was_complete && tick_complete();
  if (completed && wall_s >= 0) waited_on_[node] += std::max(0.0, wall_s - tick_sent_at_);
  return completed;
}

std::vector<std::string> ClockServer::waiting_for() const {
  std::vector<std::string> out;
  if (config_.mode != ClockMode::kLockstep) return out;
  for (const auto& n : config_.lockstep_nodes) {
    if (!satisfied(n)) out.push_back(n);
  }
  return out;
}

}  // namespace semx::runtime
