// A node's view of simulation time (DESIGN.md §3). Logic only: the Node feeds it SIM_CLOCK
// messages and acts on its decisions, so the rules are unit-tested without LCM.
//
// Rules: a higher tick is new (the node does its per-tick work, then acks in LOCKSTEP); the
// same tick again is the server resending to a late or restarted node (ack again, do no work);
// a lower tick is stale and ignored, except tick 0, which is a new episode (the clock restarts).
#pragma once

#include <cstdint>

namespace semx::runtime {

enum class ClockMode : int8_t { kRealtime = 0, kLockstep = 1 };

class SimClock {
 public:
  struct Decision {
    bool new_tick = false;  // run the per-tick work
    bool ack = false;       // publish SIM_ACK(tick) afterwards (only for lockstep participants)
    bool reset = false;     // the clock restarted at tick 0
  };

  explicit SimClock(bool lockstep_participant = false) : participant_(lockstep_participant) {}

  Decision on_clock(int64_t tick, int64_t utime, ClockMode mode);

  bool started() const { return last_tick_ >= 0; }
  int64_t now_utime() const { return utime_; }
  int64_t last_tick() const { return last_tick_; }
  ClockMode mode() const { return mode_; }
  bool participant() const { return participant_; }

 private:
  bool participant_;
  int64_t last_tick_ = -1;
  int64_t utime_ = 0;
  ClockMode mode_ = ClockMode::kRealtime;
};

}  // namespace semx::runtime
