// Lossless delivery over a lossy bus (docs/runtime.md, "Lost messages"). Every signed message
// carries its sender and its sequence number on its channel (message_auth.hpp). A receiver
// notices a loss two ways: a later message on the same stream (a gap), or a SIM_CLOCK tick whose
// heads (every publisher's last sequence number per channel, gathered by the clock from the acks)
// name a message it does not hold (a lost last message). It asks the publisher to send the
// missing ones again (SIM_RESEND) and, in lockstep, acks nothing until it holds them, so a lost
// datagram costs wall time and never changes the run. Held messages are handed over in their
// publisher's order. A publisher keeps its last messages per channel for resending.
//
// Logic only: the Node feeds it and publishes what it asks (node.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace semx::runtime {

// One publisher's channel.
struct StreamKey {
  uint64_t sender = 0;
  uint32_t tag = 0;  // channel_tag(channel) (udpm_sender.hpp)
  bool operator<(const StreamKey& o) const {
    return sender < o.sender || (sender == o.sender && tag < o.tag);
  }
};

struct StreamHead {
  StreamKey stream;
  uint32_t seq = 0;  // the last message published on it
};

struct ResendRequest {
  StreamKey stream;
  uint32_t first = 0, last = 0;
};

struct InboxCounters {
  int64_t recovered = 0;   // messages that arrived only after a resend request
  int64_t lost = 0;        // messages given up on (the publisher no longer had them, or died)
  int64_t duplicates = 0;  // a message held already (resends reach every reader)
  int64_t requests = 0;    // SIM_RESEND sent
};

class Inbox {
 public:
  struct Options {
    double retry_s = 0.05;   // wall seconds between requests for the same gap
    double give_up_s = 3.0;  // wall seconds a gap is waited for before its messages count as lost
    std::size_t max_held_bytes = 64u << 20;  // beyond it the oldest gap is given up at once
    // A reader there from its set's start owes nothing to chance: every publisher's messages are
    // for it from seq 1 (the few sent before it subscribed are still kept for resending). One
    // that joins a running set (a respawned node, an observer started later) starts with what
    // it first gets, or with the heads of its first tick.
    bool from_start = true;
  };
  explicit Inbox(uint64_t self) : self_(self) {}
  Inbox(uint64_t self, Options o) : self_(self), o_(o) {}

  // The channels read; one subscribed after the first tick takes its publishers' current heads
  // as its start (what came before was not for this reader).
  void reads(uint32_t tag);
  void set_from_start(bool b) { o_.from_start = b; }

  enum class Arrival { kDeliver, kDuplicate, kHeld };
  // A message arrived. kDeliver: hand it over now, then take ready() ones. kHeld: it follows a
  // gap; it is kept (a copy of `bytes`) and comes out of ready() once the gap is filled.
  Arrival arrive(const StreamKey& s, uint32_t seq, const std::string& channel, const uint8_t* bytes,
                 std::size_t size, double now);
  // A tick's heads: what must be held before the tick is handled. Returns true when nothing is
  // missing.
  bool tick(const std::vector<StreamHead>& heads, double now);
  // An incomplete message's own trailer said it is `seq` of the stream (LcmReassembler's tails):
  // unauthenticated, so it only makes the reader ask for the message at once, never makes it
  // wait for one or count one lost; a seq far ahead of the stream is ignored.
  void hint(const StreamKey& s, uint32_t seq);
  // True when no stream misses anything a tick or a later message said exists.
  bool complete() const;
  // The gaps to ask for now (each again every retry_s).
  std::vector<ResendRequest> requests(double now);
  // Gives up the gaps waited for longer than give_up_s (or past the held budget); their held
  // followers become ready. Returns the messages given up, as runs of sequence numbers.
  std::vector<ResendRequest> give_up(double now);

  struct Ready {
    std::string channel;
    std::vector<uint8_t> bytes;
    StreamKey stream;
    uint32_t seq = 0;
  };
  // Held messages whose turn came, in order.
  bool ready(Ready* out);

  // What a message sent again with its first counter (which the replay window refuses once it
  // saw it, or once it is old) is to this reader: one it still waits for, one it holds or handed
  // over already (counted as a duplicate), or one of a stream it does not know.
  enum class Resent { kAwaited, kDuplicate, kUnknown };
  Resent resent(const StreamKey& s, uint32_t seq);

  const InboxCounters& counters() const { return counters_; }
  void set_give_up_s(double s) { o_.give_up_s = s; }
  std::size_t held_bytes() const { return held_bytes_; }

 private:
  struct Held {
    std::string channel;
    std::vector<uint8_t> bytes;
    bool resent_for = false;
  };
  struct Stream {
    uint32_t next = 0;  // the next seq to hand over; 0: no start yet
    uint32_t want = 0;  // the last seq known to exist (from a tick or a later message)
    std::map<uint32_t, Held> held;
    double gap_since = -1;
    double last_request = -1;  // the last time missing messages were asked for again
    uint32_t asked = 0;        // everything up to here was asked for at least once
    uint32_t hinted = 0;       // the last seq an incomplete message's trailer named
  };
  bool missing(const Stream& st) const { return st.next != 0 && st.next <= st.want; }
  bool asking(const Stream& st) const { return missing(st) || (st.next != 0 && st.next <= st.hinted); }
  static constexpr uint32_t kMaxHintAhead = 64;
  void release(const StreamKey& key, Stream& st);
  void start(Stream& st, uint32_t seq_seen, bool known_from_tick);

  uint64_t self_;
  Options o_;
  std::map<StreamKey, Stream> streams_;
  std::set<uint32_t> tags_;
  std::set<uint32_t> fresh_tags_;  // read since the last tick
  bool ticked_ = false;
  std::deque<Ready> ready_;
  std::size_t held_bytes_ = 0;
  InboxCounters counters_;
};

// A publisher's last messages, for resending.
class ResendHistory {
 public:
  explicit ResendHistory(std::size_t per_channel = 64, std::size_t bytes_per_channel = 16u << 20)
      : per_channel_(per_channel), bytes_per_channel_(bytes_per_channel) {}
  // Keeps `bytes` (the signed message as sent) as message `seq` of `channel`, taking its buffer;
  // gives back an old buffer to reuse. `wire_seqno`: the transport's seqno it went with (0:
  // none), under which a resend lets readers join its fragments with those they hold.
  std::vector<uint8_t> keep(const std::string& channel, uint32_t tag, uint32_t seq,
                            std::vector<uint8_t>&& bytes, uint32_t wire_seqno = 0);
  // Message `seq` on the channel with `tag`, if still kept.
  const std::vector<uint8_t>* find(uint32_t tag, uint32_t seq, const std::string** channel,
                                   uint32_t* wire_seqno = nullptr) const;
  std::size_t bytes() const { return total_bytes_; }

 private:
  struct Kept {
    uint32_t seq;
    std::vector<uint8_t> bytes;
    uint32_t wire_seqno = 0;
  };
  struct Channel {
    std::string name;
    std::deque<Kept> kept;
    std::size_t bytes = 0;
  };
  std::size_t per_channel_, bytes_per_channel_;
  std::map<uint32_t, Channel> channels_;
  std::size_t total_bytes_ = 0;
};

}  // namespace semx::runtime
