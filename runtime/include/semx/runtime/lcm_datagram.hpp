// The receiving half of LCM's udpm wire format (lcm-proj, "UDP multicast protocol"), so a node
// can read the multicast group itself (udpm_receiver.hpp) instead of through liblcm's receive
// thread; udpm_sender.hpp writes the same format.
//
//   small message, one datagram:  "LC02" seqno(u32) channel NUL payload
//   fragment k of n:              "LC03" seqno(u32) size(u32) offset(u32) k(u16) n(u16)
//                                 [fragment 0 only: channel NUL] data
//
// Integers are big-endian. Everything a datagram claims is checked before it is believed: a
// hostile datagram is counted and dropped, and can allocate at most max_message_bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace semx::runtime {

inline constexpr uint32_t kLcmMagicShort = 0x4c433032;  // "LC02"
inline constexpr uint32_t kLcmMagicLong = 0x4c433033;   // "LC03"
inline constexpr std::size_t kLcmShortHeader = 8;
inline constexpr std::size_t kLcmLongHeader = 20;
inline constexpr std::size_t kLcmMaxChannel = 63;  // liblcm refuses to publish longer names

enum class DatagramError {
  kNone,
  kTooShort,  // shorter than its header
  kMagic,     // neither LC02 nor LC03
  kChannel,   // no NUL within kLcmMaxChannel + 1 bytes, or an empty name
  kFragment,  // fragment number, count, offset or size inconsistent
  kTooLarge,  // the message would exceed max_message_bytes
};
const char* to_string(DatagramError e);

struct LcmMessageView {
  const std::string* channel = nullptr;
  const uint8_t* data = nullptr;
  std::size_t size = 0;
};

struct ReassemblyCounters {
  int64_t datagrams = 0;
  int64_t rejected = 0;    // datagrams with a DatagramError
  int64_t orphans = 0;     // fragments of a message whose first fragment was not seen (the
                           // kernel filter drops the first fragment of unsubscribed channels)
  int64_t incomplete = 0;  // messages abandoned with fragments missing (a lost datagram)
};

// Rebuilds messages from the datagrams of any number of senders, with liblcm's rules: a message
// starts with its fragment 0 (which names the channel), the other fragments may follow in any
// order, and a sender's next message abandons its previous incomplete one.
class LcmReassembler {
 public:
  explicit LcmReassembler(std::size_t max_message_bytes);

  // Feeds one datagram from `sender` (address and port). Returns kNone when it was well formed;
  // `*complete` then says whether it finished a message, which `*out` points at until the next
  // call.
  DatagramError feed(uint64_t sender, const uint8_t* data, std::size_t size, LcmMessageView* out,
                     bool* complete);

  const ReassemblyCounters& counters() const { return counters_; }
  // Bytes held for messages still missing fragments: at most the larger of
  // 2 x max_message_bytes and 64 MiB, whatever the senders claim.
  std::size_t pending_bytes() const { return pending_bytes_; }

 private:
  struct Pending {
    uint64_t started = 0;  // order of first fragments, for evicting the oldest
    uint32_t seqno = 0;
    uint32_t size = 0;
    uint16_t remaining = 0;
    std::vector<bool> seen;
    std::string channel;
    std::vector<uint8_t> data;
  };
  // Bounds what hostile senders on many ports can hold at once.
  static constexpr std::size_t kMaxPendingSenders = 32;
  // Abandons the oldest incomplete messages (not `keep`'s) until `bytes` more fit the budget and,
  // when `adding` a sender, the number of senders.
  void make_room(std::size_t bytes, uint64_t keep, bool adding);

  DatagramError feed_fragment(uint64_t sender, const uint8_t* data, std::size_t size, LcmMessageView* out,
                              bool* complete);

  std::size_t max_message_bytes_;
  std::map<uint64_t, Pending> pending_;
  std::size_t pending_bytes_ = 0;
  std::size_t pending_budget_;
  uint64_t started_ = 0;
  std::string channel_;  // the last small message's channel, for the view
  std::vector<uint8_t> done_;
  ReassemblyCounters counters_;
};

// Reads a channel name that starts at `p` with `left` bytes after it; returns its length, or -1
// when there is no NUL within kLcmMaxChannel + 1 bytes or the name is empty.
int lcm_channel_length(const uint8_t* p, std::size_t left);

}  // namespace semx::runtime
