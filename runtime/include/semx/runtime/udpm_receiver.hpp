// A node's own reader of an LCM udpm multicast group.
//
// liblcm 1.3 reads the group on a thread of its own and hands each message to the main thread
// through a pipe, and it reads every datagram on the group, also those of channels the process
// never subscribed to. In a lockstep set every tick's few small messages (clock, odometry,
// commands, acks) therefore woke every thread of every process. This reader runs on the caller's
// thread and gives the socket a kernel filter (classic BPF) that drops, before any process wakes,
// the datagrams of channels it does not read. The bytes on the wire are liblcm's, so lcm-logger,
// lcm-spy and liblcm processes share the group as before.
#pragma once

#include <linux/filter.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <queue>
#include <string>
#include <vector>

#include "semx/runtime/lcm_datagram.hpp"

namespace semx::runtime {

// What "udpm://GROUP:PORT?ttl=N&recv_buf_size=BYTES" names.
struct UdpmEndpoint {
  std::string group;
  int port = 0;
  int ttl = 0;            // 0: nothing leaves the host
  int recv_buf_size = 0;  // 0: kDefaultRecvBufBytes
};

// A receiver's buffer when the URL names none: a burst of 1 MB camera frames and map messages
// within the lockstep clock's slack must fit.
inline constexpr int kDefaultRecvBufBytes = 4 << 20;

// The endpoint of a udpm URL; nullopt for any other provider and for URLs this parser does not
// understand (liblcm's own receiver then takes them as before).
std::optional<UdpmEndpoint> parse_udpm_url(const std::string& url);

// A classic BPF program for a UDP socket (offset 0 is the UDP header) that passes the LCM
// datagrams of `channels` (exact names) and drops the rest, or, with `refuse`, drops those of
// `channels` and passes the rest. Fragments after the first name no channel: one whose sequence
// number carries a channel tag (udpm_sender.hpp) is judged by the tag, an untagged one (liblcm's
// senders) always passes; the reassembler drops those whose first fragment was refused. Fragments
// sent again (SXR3, lcm_datagram.hpp) are all judged by their tag.
std::vector<sock_filter> lcm_channel_filter(const std::vector<std::string>& channels, bool refuse = false);

class UdpmReceiver {
 public:
  // Opens, filters (nothing passes until filter() is called), binds and joins the group. Throws
  // std::runtime_error naming the endpoint and the failing call.
  UdpmReceiver(const UdpmEndpoint& endpoint, std::size_t max_message_bytes);
  ~UdpmReceiver();
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;

  // The channels the kernel lets through: exactly `channels`; or, when `all`, every channel but
  // `refused` (a hint: channels it does not drop are still refused by the caller).
  void filter(const std::vector<std::string>& channels, bool all,
              const std::vector<std::string>& refused = {});

  // The next complete message from the datagrams queued now, without waiting; false when none
  // completes. The view is valid until the next call. A bad datagram is counted and skipped, and
  // its reason left in last_error().
  bool next(LcmMessageView* out);
  // Waits up to timeout_ms for a datagram (or a delayed one's turn); false on timeout or a signal.
  bool wait(int timeout_ms) const;

  int fd() const { return fd_; }
  // Incomplete messages' last bytes (LcmReassembler::report_tails).
  void report_tails(std::size_t bytes) { reassembler_.report_tails(bytes); }
  bool next_tail(LcmReassembler::Tail* out) { return reassembler_.next_tail(out); }
  const ReassemblyCounters& counters() const { return reassembler_.counters(); }
  DatagramError last_error() const { return last_error_; }
  int64_t socket_errors() const { return socket_errors_; }
  // The receive buffer asked for and the one the kernel granted (after SO_RCVBUFFORCE, which only
  // root may use): less than asked means bursts are dropped by the kernel.
  int requested_recv_buf() const { return requested_recv_buf_; }
  // For tests of a lossy bus: drops each datagram with probability `rate` (seeded), as a lossy
  // network would, before reassembly. Node sets it from SEMX_TEST_DROP_RATE.
  void drop_for_test(double rate, uint64_t seed) {
    drop_rate_ = rate;
    drop_state_ = seed * 0x9E3779B97F4A7C15ull + 1;
  }
  int64_t dropped_for_test() const { return dropped_for_test_; }
  // For tests of a bus with jitter: each datagram is handed to reassembly `uniform(0, max_s)`
  // seconds after it came (seeded), independently of the others, so datagrams and the fragments
  // of one message come out of order, as on a loaded network. Node sets it from
  // SEMX_TEST_JITTER_MS.
  void delay_for_test(double max_s, uint64_t seed) {
    delay_max_s_ = max_s;
    delay_state_ = seed * 0xBF58476D1CE4E5B9ull + 1;
  }
  int granted_recv_buf() const { return granted_recv_buf_; }

 private:
  int fd_ = -1;
  std::vector<uint8_t> buffer_;
  LcmReassembler reassembler_;
  DatagramError last_error_ = DatagramError::kNone;
  int64_t socket_errors_ = 0;
  int requested_recv_buf_ = 0;
  double drop_rate_ = 0;
  uint64_t drop_state_ = 1;
  int64_t dropped_for_test_ = 0;
  int granted_recv_buf_ = 0;
  std::string name_;
  struct Delayed {
    double due = 0;
    uint64_t order = 0;
    uint64_t sender = 0;
    std::vector<uint8_t> bytes;
    bool operator>(const Delayed& o) const { return due > o.due || (due == o.due && order > o.order); }
  };
  bool read_datagram(std::size_t* n, uint64_t* sender);  // false when none is queued
  bool drop_now();
  bool next_delayed(LcmMessageView* out);
  double delay_max_s_ = 0;
  uint64_t delay_state_ = 1;
  uint64_t delay_order_ = 0;
  std::priority_queue<Delayed, std::vector<Delayed>, std::greater<Delayed>> delayed_;
  std::vector<uint8_t> current_;  // the delayed datagram a view may point into
};

}  // namespace semx::runtime
