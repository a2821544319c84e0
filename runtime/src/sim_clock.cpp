#include "semx/runtime/sim_clock.hpp"

namespace semx::runtime {

SimClock::Decision SimClock::on_clock(int64_t tick, int64_t utime, ClockMode mode) {
  Decision d;
  if (tick < 0 || utime < 0) return d;
  const bool lockstep_ack = participant_ && mode == ClockMode::kLockstep;
  if (tick > last_tick_ || (tick == 0 && last_tick_ > 0)) {
    d.reset = tick == 0 && last_tick_ > 0;
    // Time never runs backwards within an episode, whatever a sender claims.
    if (d.reset || utime >= utime_) utime_ = utime;
    last_tick_ = tick;
    mode_ = mode;
    d.new_tick = true;
    d.ack = lockstep_ack;
  } else if (tick == last_tick_) {
    d.ack = lockstep_ack;
  }
  return d;
}

}  // namespace semx::runtime
