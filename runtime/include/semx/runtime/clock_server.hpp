// The source of simulation time (DESIGN.md §3): decides when the next SIM_CLOCK tick is due.
// Logic only; the simulator and semx-clock publish what it decides.
//
// REALTIME: tick k is due at wall time start + k * period / speed, and nobody is waited for.
// LOCKSTEP: tick k+1 is due as soon as every registered node has acked tick k; while some have
// not, tick k is resent every `resend_after_s` (wall) so a node that started late or restarted
// still gets it. Acks are matched by node name and tick, so duplicates and strays are harmless.
// A node's latest ack may promise quiet until a later time (ack_t.quiet_until): the clock then
// does not wait for it on the ticks before that time, up to `max_slack_us` after the acked tick,
// which bounds how far behind a node falls (what its receive buffer must hold). Its outputs
// still come before the ack of a waited tick, so every reader sees the same order: the run is
// the one the fully waited clock gives, with the nodes that have nothing to say off the critical
// path (docs/runtime.md, "Promised quiet").
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "semx/runtime/sim_clock.hpp"

namespace semx::runtime {

struct ClockServerConfig {
  ClockMode mode = ClockMode::kRealtime;
  int64_t period_us = 10000;  // 100 Hz: the odometry rate
  double speed = 1.0;         // REALTIME only
  double max_speed = 0.0;     // LOCKSTEP: never faster than this many simulated s per wall s (0: no cap)
  std::vector<std::string> lockstep_nodes;  // LOCKSTEP: who must ack every tick
  // A lost tick or ack costs this much wall time (a 10 % lossy bus loses one every few ticks;
  // at 0.5 s a 43 s env1 run took 817 s).
  double resend_after_s = 0.05;
  int64_t max_slack_us = 100000;  // LOCKSTEP: a promise counts at most this far past its tick
  int64_t max_ticks = -1;         // stop after this many ticks (-1: never)
};

struct ClockTick {
  int64_t tick;
  int64_t utime;
  bool resend;  // the same tick again, not a new one
};

class ClockServer {
 public:
  explicit ClockServer(ClockServerConfig config);

  // What to publish at wall time `wall_s` (monotonic seconds), if anything. `inputs_held` false
  // (the clock's own node misses a message an ack named: Node::holds_everything) holds the next
  // tick back in LOCKSTEP, as a missing ack would.
  std::optional<ClockTick> poll(double wall_s, bool inputs_held = true);
  // A clock source that was restarted continues at `tick` (the last one it published before it
  // died; ticks never go backwards): the first poll() resends it, in LOCKSTEP until every node
  // acked it again, and time goes on from there.
  void resume(int64_t tick, double wall_s);
  // Records an ack (with its promise, 0 for none) received at wall time `wall_s` (< 0: unknown);
  // returns true if it completed the current tick's set.
  bool on_ack(const std::string& node, int64_t tick, int64_t quiet_until = 0, double wall_s = -1.0);
  // The current tick actually went out at `wall_s` (after the simulator stepped and published its
  // sensors): waits are counted from here.
  void mark_published(double wall_s) { tick_sent_at_ = wall_s; }
  // LOCKSTEP: per node, the wall seconds from a tick's first sending to the ack that completed
  // its set, when that ack was the node's: whom the clock waited on, and how long (what to make
  // faster for a faster lockstep run).
  const std::map<std::string, double>& waited_on() const { return waited_on_; }

  bool finished() const;  // max_ticks reached (and acked, in LOCKSTEP)
  int64_t current_tick() const { return tick_; }
  int64_t current_utime() const { return tick_ < 0 ? 0 : tick_ * config_.period_us; }
  std::vector<std::string> waiting_for() const;  // LOCKSTEP: nodes that have not acked yet
  double seconds_waiting(double wall_s) const { return wall_s - tick_sent_at_; }
  const ClockServerConfig& config() const { return config_; }

 private:
  bool tick_complete() const;

  ClockServerConfig config_;
  int64_t tick_ = -1;
  double start_wall_ = -1;
  double tick_sent_at_ = 0;
  double last_send_ = 0;
  struct NodeAcks {
    int64_t tick = -1;        // the latest tick acked
    int64_t quiet_until = 0;  // promised with it (capped)
  };
  bool satisfied(const std::string& node) const;

  std::map<std::string, NodeAcks> acks_;
  std::map<std::string, double> waited_on_;
};

}  // namespace semx::runtime
