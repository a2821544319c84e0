// The receiving half of LCM's udpm wire format (lcm-proj, "UDP multicast protocol"), so a node
// can read the multicast group itself (udpm_receiver.hpp) instead of through liblcm's receive
// thread; udpm_sender.hpp writes the same format.
//
//   small message, one datagram:  "LC02" seqno(u32) channel NUL payload
//   fragment k of n:              "LC03" seqno(u32) size(u32) offset(u32) k(u16) n(u16)
//                                 [fragment 0 only: channel NUL] data
//   the same fragment sent again: "SXR3" and the rest as its LC03 original
//
// The SXR3 form is semx's: a publisher asked for a lost message (delivery.hpp) sends the very
// bytes again under the original seqno, so a reader joins them with the fragments it holds of
// the first copy, and each copy only has to fill what the others lost. At 10 % datagram loss a
// 1.2 MB ESDF window of 19 fragments arrives whole 13 % of the times it is sent, and a resend
// that has to arrive whole is lost as often; filling holes needs one good copy of each fragment.
// liblcm's readers (lcm-logger, lcm-spy) do not know the magic and ignore it: liblcm counts
// fragments rather than marking them, so a repeated fragment would let it deliver a message with
// a hole.
//
// Integers are big-endian. Everything a datagram claims is checked before it is believed: a
// hostile datagram is counted and dropped, and can allocate at most max_message_bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace semx::runtime {

inline constexpr uint32_t kLcmMagicShort = 0x4c433032;    // "LC02"
inline constexpr uint32_t kLcmMagicLong = 0x4c433033;     // "LC03"
inline constexpr uint32_t kSemxMagicResend = 0x53585233;  // "SXR3"
inline constexpr std::size_t kLcmShortHeader = 8;
inline constexpr std::size_t kLcmLongHeader = 20;
inline constexpr std::size_t kLcmMaxChannel = 63;  // liblcm refuses to publish longer names

enum class DatagramError {
  kNone,
  kTooShort,  // shorter than its header
  kMagic,     // neither LC02, LC03 nor SXR3
  kChannel,   // no NUL within kLcmMaxChannel + 1 bytes, or an empty name
  kFragment,  // fragment number, count, offset or size inconsistent
  kTooLarge,  // the message would exceed max_message_bytes
};
const char* to_string(DatagramError e);

// seqno = kSeqnoTagged | tag << 8 | counter (udpm_sender.hpp): liblcm's senders count from 0
// and reach the marker only after 2^32 - 2^28 messages, so their fragments stay untagged. A
// receiver only compares a sender's seqnos for equality, and one sender's consecutive messages
// differ in the counter or the tag.
inline constexpr uint32_t kSeqnoTagMask = 0xF0000000u;
inline constexpr uint32_t kSeqnoTagged = 0xF0000000u;
inline constexpr int kSeqnoTagShift = 8;
inline constexpr uint32_t kSeqnoTagBits = 0xFFFFFu;
inline bool seqno_tagged(uint32_t seqno) { return (seqno & kSeqnoTagMask) == kSeqnoTagged; }

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
  int64_t filled = 0;      // messages completed with fragments of a copy sent again (SXR3)
  int64_t spare = 0;       // SXR3 fragments of a message already complete, or held already
};

// Rebuilds messages from the datagrams of any number of senders. A message is complete when each
// of its fragments came once, from its first sending or a resend (SXR3), in any order. Unlike
// liblcm, a sender's next message does not abandon its previous incomplete one: on a bus with
// jitter a sender's messages arrive interleaved, and a lost fragment may still come again. Each
// sender keeps at most kMaxPendingPerSender incomplete messages (the oldest is abandoned). A
// fragment after the first may start a message only when its seqno carries a channel tag (it
// passed the kernel filter for a channel this reader wants); liblcm's untagged ones follow their
// first fragment, as liblcm's rule has it.
class LcmReassembler {
 public:
  explicit LcmReassembler(std::size_t max_message_bytes);

  static constexpr std::size_t kMaxPending = 128;  // bounds hostile senders on many ports
  // A simulator sends ~60 frames a second, most of them incomplete at 10 % loss until a resend
  // fills them, a resend taking up to 0.1 s with jitter.
  static constexpr std::size_t kMaxPendingPerSender = 48;
  // How long a completed message's seqno stays known, so that the rest of a resend that came
  // after it completed starts nothing.
  static constexpr double kDoneMemoryS = 0.5;
  // An incomplete message older than this is abandoned when its seqno comes again: the sender's
  // 8-bit counter came round (a resend comes within tens of milliseconds).
  static constexpr double kPendingMaxAgeS = 1.0;

  // Feeds one datagram from `sender` (address and port), received at `now_s` (a monotonic clock).
  // Returns kNone when it was well formed; `*complete` then says whether it finished a message,
  // which `*out` points at until the next call.
  DatagramError feed(uint64_t sender, const uint8_t* data, std::size_t size, LcmMessageView* out,
                     bool* complete, double now_s = 0);

  const ReassemblyCounters& counters() const { return counters_; }

  // The last `bytes` of a message whose last fragment came while others are still missing, once
  // per message: where semx's trailer (message_auth.hpp) names the message's stream and seq, so
  // the reader can ask for it again at once. 0 (the default): not reported.
  struct Tail {
    uint64_t sender = 0;
    uint32_t seqno = 0;
    std::vector<uint8_t> bytes;
  };
  void report_tails(std::size_t bytes) { tail_bytes_ = bytes; }
  bool next_tail(Tail* out);
  // Bytes held for messages still missing fragments: at most the larger of
  // 2 x max_message_bytes and 64 MiB, whatever the senders claim.
  std::size_t pending_bytes() const { return pending_bytes_; }

 private:
  struct Key {
    uint64_t sender = 0;
    uint32_t seqno = 0;
    bool operator<(const Key& o) const {
      return sender < o.sender || (sender == o.sender && seqno < o.seqno);
    }
    bool operator==(const Key& o) const { return sender == o.sender && seqno == o.seqno; }
  };
  struct Pending {
    uint64_t started = 0;  // order of creation, for evicting the oldest
    double created_s = 0;
    uint32_t size = 0;
    uint16_t count = 0;
    uint16_t remaining = 0;
    bool resent = false;  // a fragment came from a resend
    bool tail_told = false;
    std::vector<bool> seen;
    std::string channel;  // known once fragment 0 came
    std::vector<uint8_t> data;
  };
  struct Done {
    Key key;
    uint32_t size = 0;
    double at = 0;
  };
  // Abandons the oldest incomplete messages until `bytes` more fit the budget, one more fits
  // kMaxPending, and one more of `sender` fits kMaxPendingPerSender.
  void make_room(std::size_t bytes, uint64_t sender);
  void abandon(std::map<Key, Pending>::iterator it);
  bool recently_done(const Key& key, uint32_t size, double now_s);

  DatagramError feed_fragment(uint64_t sender, const uint8_t* data, std::size_t size, LcmMessageView* out,
                              bool* complete, bool resend, double now_s);

  std::size_t max_message_bytes_;
  std::map<Key, Pending> pending_;
  std::vector<Done> done_recent_;  // completed messages of the last kDoneMemoryS, oldest first
  static constexpr std::size_t kMaxTails = 256;
  std::size_t tail_bytes_ = 0;
  std::deque<Tail> tails_;
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
