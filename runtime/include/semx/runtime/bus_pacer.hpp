// Spreads a sender's datagrams over wall time, for readers that hold little: a liblcm program
// started by hand (lcm-logger) gets the kernel's default receive buffer (208 KiB, 416 KiB with
// the kernel's bookkeeping) and queues at most 30 messages, while a lockstep set, faster than
// real time, writes a 600 KB depth frame or a 1.2 MB ESDF window in a fraction of a millisecond.
// Whatever such a reader does not take in time the kernel or liblcm drops without a word. A
// token bucket: `burst_bytes` may go at once, the rest at `bytes_per_s`; every datagram costs at
// least `datagram_bytes`, which bounds the message rate too. The sender sleeps the delay, and
// on a busy machine that sleep is what lets the reader run.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace semx::runtime {

struct BusPace {
  double bytes_per_s = 0;     // 0: no pacing
  double burst_bytes = 0;     // what may go at once
  double datagram_bytes = 0;  // the least a datagram costs
};

// SEMX_BUS_PACE="MB_PER_S[:BURST_KB[:DATAGRAM_KB]]" (MB = 10^6 bytes, KB = 10^3), e.g. "40:128:1";
// "0" or "" is no pacing. nullopt for anything else (the caller names the variable).
std::optional<BusPace> parse_bus_pace(const std::string& text);
// The pacing SEMX_BUS_PACE asks for (none when unset); throws std::runtime_error naming the
// variable and its value when it is not a pace.
BusPace bus_pace_from_env();

class BusPacer {
 public:
  explicit BusPacer(BusPace pace);

  bool active() const { return pace_.bytes_per_s > 0; }
  // Takes a datagram of `bytes` sent at wall time `now_s` (monotonic seconds); returns how long
  // to wait before sending it (0: at once). Waiting that long and calling again later is what
  // the bucket expects: the debt is paid by the time that passes.
  double delay(std::size_t bytes, double now_s);

 private:
  BusPace pace_;
  double tokens_;
  double last_s_ = -1;
};

}  // namespace semx::runtime
