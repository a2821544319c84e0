// Wall time for transport timers (resend retries, give-ups, pacing, reassembly ages): a monotonic
// clock, never the message time that all logic runs on.
#pragma once

#include <chrono>

namespace semx::runtime {

inline double monotonic_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace semx::runtime
