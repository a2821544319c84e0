// The LCM side of every semx process: typed, validated subscriptions, publishing, the
// simulation clock, the NODE_STATUS heartbeat and clean shutdown.
//
// Every byte that arrives is counted. A message is handed to a handler only after its wire
// layout was checked (wire_validator.hpp), the generated decoder succeeded inside try/catch and
// the optional `accept` predicate agreed; anything else is counted as malformed and dropped.
// Exceptions from handlers are caught and counted: nothing a sender does can escape handle().
// One thread uses a node, publishing included (a worker hands its bytes to that thread, as the
// mapper's does): the udpm transport keeps no locks.
#pragma once

#include <atomic>

#include <lcm/lcm-cpp.hpp>
#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/resend_t.hpp>

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "semx/runtime/channel_pattern.hpp"
#include "semx/runtime/delivery.hpp"
#include "semx/runtime/lcm_schema.hpp"
#include "semx/runtime/message_auth.hpp"
#include "semx/runtime/parent_watch.hpp"
#include "semx/runtime/restart_count.hpp"
#include "semx/runtime/sim_clock.hpp"
#include "semx/runtime/udpm_receiver.hpp"
#include "semx/runtime/udpm_sender.hpp"
#include "semx/runtime/wire_validator.hpp"

namespace semx::runtime {

class NodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct NodeOptions {
  std::string name;
  std::string lcm_url;                        // empty: resolve_lcm_url("")
  bool lockstep = false;                      // ack every SIM_CLOCK tick (a registered lockstep node)
  bool follow_clock = true;                   // subscribe to SIM_CLOCK (off for the clock's source)
  double status_period_s = 1.0;               // NODE_STATUS heartbeat, wall clock
  std::size_t max_message_bytes = 32u << 20;  // larger messages are dropped unread
  bool quiet = false;                         // no log lines for dropped messages
  // Repeat the first NODE_STATUS after kAnnounceDelaysS (wall), before the heartbeat settles to
  // status_period_s: a process started at the same time (the lockstep simulator, which waits to
  // hear every node it must wait for) hears this one within a fraction of a second, not a period.
  bool announce = false;
  // The set's key file (--auth-key); empty: SEMX_AUTH_KEY / SEMX_AUTH_KEY_FILE, else the open
  // session (message_auth.hpp).
  std::string auth_key_file;
  // Off only for tools that play an outsider (semx-hostile --unsigned): messages go out without a
  // trailer, and every semx node drops them.
  bool sign = true;
  // A process that watches a set and changes nothing of its run (recorder, monitor, viewer): its
  // lost messages make a log or a picture incomplete, not the run invalid (NODE_STATUS observer).
  bool observer = false;
  // How often the launcher restarted this process (restart_count.hpp), reported in NODE_STATUS.
  int restarts = restart_count();
};

struct ChannelCounters {
  bool outgoing = false;
  int64_t messages = 0;
  int64_t malformed = 0;
  int64_t dropped = 0;
  int64_t bytes = 0;
  int64_t skipped = 0;  // refused by a skip_unless() filter before decoding (not malformed)
  int64_t foreign = 0;  // another set's messages (another session on the same bus)
  int64_t refused = 0;  // unsigned, forged or replayed
};

struct NodeCounters {
  int64_t received = 0;
  int64_t sent = 0;
  int64_t dropped = 0;    // includes messages whose fragments did not all arrive
  int64_t malformed = 0;  // includes datagrams that are not LCM's (udpm_receiver.hpp)
  int64_t handler_errors = 0;
  int64_t foreign = 0;    // another set's messages, ignored
  int64_t refused = 0;    // unsigned, forged or replayed messages, dropped
  int64_t lost = 0;       // messages missed and given up on (delivery.hpp): the run is not exact
  int64_t recovered = 0;  // messages missed and received again after a SIM_RESEND
  int64_t resent = 0;     // messages this node sent again on request
};

enum class NodeState : int8_t {
  kStarting = 0,
  kRunning = 1,
  kDegraded = 2,
  kDone = 3,
  kStopping = 4,
  kFailed = 5
};
const char* to_string(NodeState s);

// Set by SIGINT/SIGTERM once install_shutdown_handlers() ran.
void install_shutdown_handlers();
bool shutdown_requested();
void request_shutdown();

class Node {
 public:
  explicit Node(NodeOptions options);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  const std::string& name() const { return options_.name; }
  const std::string& url() const { return options_.lcm_url; }
  // True when this node reads and writes a udpm group itself, with a kernel filter for its
  // channels (udpm_receiver.hpp, udpm_sender.hpp); false when liblcm does (other providers, or
  // SEMX_LCM_TRANSPORT=liblcm in the environment).
  bool own_receiver() const { return udpm_.has_value(); }

  // Typed subscription to one channel. `accept` may reject decoded messages whose content is
  // unusable (NaN poses, inconsistent sizes): they count as malformed.
  template <class T>
  void subscribe(const std::string& channel, std::function<void(const T&)> handler,
                 std::function<bool(const T&)> accept = nullptr);
  // Messages with a NaN or inf never reach a handler, except on the channels named here, whose
  // subscribers judge such content themselves and answer it: the controller tells the planner
  // that a path with a NaN waypoint is REJECTED, so the planner plans again rather than waiting
  // for a path that never runs.
  void judges_non_finite(const std::string& channel);
  // Cheap early out for large messages a node only needs some of: a message on `channel` whose
  // utime (every semx type's first field, read straight from the bytes) makes `wanted` false is
  // counted (ChannelCounters::skipped) and dropped before it is validated or decoded. Messages
  // too short to hold a utime go through the normal checks.
  void skip_unless(const std::string& channel, std::function<bool(int64_t utime)> wanted);
  // Raw bytes of every channel matching `regex` (tools: monitors, recorders): the payload LCM's
  // decoders read, or with `with_trailer` the message as it came (a recorder keeps the trailer,
  // so a log replayed with the run's key is accepted again). Only this set's authenticated
  // messages reach it, as they reach typed subscriptions.
  using RawHandler = std::function<void(const std::string& channel, const uint8_t* data, std::size_t size)>;
  void subscribe_raw(const std::string& regex, RawHandler handler, bool with_trailer = false);
  // With a pattern subscription every channel reaches this process; these exact channels, which
  // its handlers ignore anyway (a recorder's exclusions), the kernel may drop before they do.
  void never_wanted(std::vector<std::string> channels);

  template <class T>
  bool publish(const std::string& channel, const T& msg);
  bool publish_raw(const std::string& channel, const void* data, std::size_t size);

  // Called for each new SIM_CLOCK tick, before this node acks it in LOCKSTEP.
  void on_tick(std::function<void(int64_t tick, int64_t utime)> fn) {
    tick_handlers_.push_back(std::move(fn));
  }
  // From a tick handler: run `fn` after this tick's ack (at once when nothing is acked), so the
  // clock can go on meanwhile up to the promised quiet_until. Work that publishes nothing before
  // its promise (a planning cycle whose outputs are charged time) then overlaps other nodes'.
  void after_ack(std::function<void()> fn) { after_ack_.push_back(std::move(fn)); }
  const SimClock& clock() const { return clock_; }
  // True when no message a tick's or an ack's heads named is missing (delivery.hpp). The clock's
  // source issues the next lockstep tick only then.
  bool holds_everything() const { return inbox_.complete(); }
  int64_t now_utime() const { return clock_.now_utime(); }
  // LOCKSTEP: asked after the tick handlers, before each ack: the earliest message time at which
  // this node may publish again, whatever it receives meanwhile (its own schedule: next cycle,
  // next frame the gate takes, next periodic output). Sent in SIM_ACK, so the clock does not wait
  // for this node on the ticks before it. Without one (or <= the tick), every tick is waited for.
  // A node must keep its promise: may_publish() says whether the current tick is past it.
  void on_quiet_until(std::function<int64_t(int64_t utime)> fn) { quiet_until_fn_ = std::move(fn); }
  // Within its promise a node acks a new tick only every kAckIntervalUs of message time: the clock
  // does not wait for those acks, and each one woke every process on the bus (five a tick were
  // half the run's messages). The clock counts a promise at most ClockServerConfig::max_slack_us
  // (100 ms) past the acked tick, so it never waits for a skipped one. Resent ticks are acked.
  static constexpr int64_t kAckIntervalUs = 50000;
  static constexpr double kAnnounceDelaysS[] = {0.05, 0.1, 0.2, 0.4};
  bool may_publish() const;
  // Drops this node's last promise: for a node that saw no tick for a while of wall time (the
  // simulator ended) and must answer anyway (the mapper's last snapshot request).
  void release_promise() { quiet_until_ = 0; }
  // Publications on ticks this node had promised to be quiet (a broken promise makes a lockstep
  // run depend on scheduling); NODE_STATUS and SIM_ACK do not count.
  int64_t early_publishes() const { return early_publishes_; }
  // For the clock's source, which does not follow SIM_CLOCK: its own current time and mode (the
  // mode sets how long a lost message is waited for: a lockstep clock source that took itself
  // for realtime gave up on a lost CONTROL_CMD after 0.3 s, and the run was not valid).
  void set_time(int64_t utime, int64_t tick, ClockMode mode);

  void set_state(NodeState state, const std::string& detail = "");
  NodeState state() const { return state_; }

  // Waits up to `timeout_ms` for a message and handles it; sends the heartbeat when due.
  // Returns 1 if a message was handled, 0 on timeout, -1 if the LCM provider failed.
  int spin_once(int timeout_ms);
  // Handles everything already queued, without waiting; returns how many messages.
  int drain();
  // Spins until shutdown_requested() or stop(); returns a process exit code.
  int run();
  // The one call another thread may make: ends run() (and loops on stopped()) after its spin.
  void stop() { stop_ = true; }
  bool stopped() const { return stop_ || shutdown_requested(); }

  const NodeCounters& counters() const { return counters_; }
  const std::map<std::string, ChannelCounters>& incoming() const { return incoming_; }
  const std::map<std::string, ChannelCounters>& outgoing() const { return outgoing_; }
  semx::node_status_t status() const;
  void publish_status();
  // The set this node belongs to (message_auth.hpp) and its own sender id.
  uint64_t session() const { return verifier_.session(); }
  uint64_t sender() const { return signer_.sender(); }
  bool open_session() const { return key_.is_open(); }

 private:
  using Heads = std::map<StreamKey, uint32_t>;  // (sender, channel) -> the last seq published
  struct Subscription;
  template <class T>
  struct TypedSubscription;
  enum class Outcome { kDelivered, kMalformed, kHandlerError };

  void ensure_lcm_subscription(const std::string& channel);
  void on_lcm_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_lcm_raw_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  // Every message that arrives: its trailer is checked, then it goes to the typed and raw handlers.
  void on_signed_message(const std::string& channel, const uint8_t* data, std::size_t size);
  void on_message(const std::string& channel, const uint8_t* data, std::size_t size);
  void on_raw_message(const std::string& channel, const uint8_t* data, std::size_t size, std::size_t payload);
  void note_refused(const std::string& channel, AuthVerdict verdict, const AuthTrailer& trailer);
  // Signs `bytes` (the payload) in place and sends it.
  bool send_signed(const std::string& channel, std::vector<uint8_t>& bytes);
  // Own receiver: opens it on the first subscription and keeps its kernel filter current.
  void update_receiver();
  int receive_once(int wait_ms);
  void note_receiver_problems();
  void on_clock_message(const semx::clock_t& msg);
  // The tick's work and ack (`may_ack`), once everything its heads name is held.
  void handle_tick(const semx::clock_t& msg, bool may_ack);
  // The tick in its turn: the LOCKSTEP ticks before it this node lost for good, the messages its
  // heads name, the tick (first of held_ticks_ when `held`), what may follow it at once.
  void handle_tick_in_turn(const semx::clock_t& msg, const Heads& heads, bool held);
  // Resend requests, given-up gaps, held ticks whose messages all arrived.
  void service_delivery();
  // Hands a message to the typed subscriptions (`payload` bytes) and raw ones (`size` bytes).
  void dispatch(const std::string& channel, const uint8_t* data, std::size_t size, std::size_t payload);
  void deliver_ready();
  void on_resend_request(const semx::resend_t& r);
  // The clock's source: its SIM_CLOCK carries every publisher's heads.
  bool publish_clock(const std::string& channel, const semx::clock_t& msg);
  std::vector<std::pair<int32_t, int32_t>> own_heads() const;
  void note_malformed(const std::string& channel, const std::string& why, std::size_t size);
  void note_handler_error(const std::string& channel, const char* what);
  const LcmStruct& schema_of(const char* type_name) const;
  void note_non_finite_publish(const std::string& channel);

  NodeOptions options_;
  std::unique_ptr<lcm::LCM> lcm_;  // other providers only
  std::map<std::string, std::vector<std::unique_ptr<Subscription>>> subs_;
  struct RawSubscription {
    ChannelPattern pattern;
    RawHandler handler;
    bool with_trailer = false;
  };
  std::vector<RawSubscription> raw_handlers_;
  std::optional<UdpmEndpoint> udpm_;
  std::unique_ptr<UdpmReceiver> receiver_;
  std::unique_ptr<UdpmSender> sender_;
  std::vector<std::string> receive_channels_;
  std::vector<std::string> never_wanted_;
  ReassemblyCounters receiver_seen_;  // what the counters already hold of the receiver's
  std::map<std::string, std::function<bool(int64_t)>> skip_filters_;
  std::vector<uint8_t> encode_buffer_;
  std::vector<uint8_t> publish_buffer_;  // publish_raw's copy, with room for the trailer
  AuthKey key_;
  MessageSigner signer_;
  MessageVerifier verifier_;
  Inbox inbox_;
  ResendHistory history_;
  std::vector<uint8_t> resend_buffer_;
  // LOCKSTEP: a message is handed over right before the first tick whose heads name it (the
  // tick its publisher's next ack led to), so a node handles each tick with the messages a
  // lossless bus gives it before that tick, whatever the order they came in (docs/runtime.md,
  // "Lost messages"). Without it, a node that lost a SIM_CLOCK tick applied the other nodes'
  // answers to that tick (a new path, an ESDF) before the tick when it came again, and a
  // controller stepped with an ESDF the mapper sent during the tick: another run. Messages of
  // senders that never ack (tools, a node before its first ack), all of REALTIME and an
  // observer's between ticks go at once.
  // Ticks waiting for messages their heads name, with those heads.
  struct HeldTick {
    semx::clock_t msg;
    Heads heads;
  };
  std::deque<HeldTick> held_ticks_;
  std::deque<Inbox::Ready> deferred_;  // messages waiting for the tick that names them
  Heads tick_heads_;                   // the handled ticks' heads
  std::set<uint64_t> acking_senders_;  // senders a tick's heads named
  static bool named(const Heads& heads, const StreamKey& stream, uint32_t seq);
  // True when a message may be handed over before the next tick (own ones, those the next
  // held tick or the last handled one names, those of senders that do not ack).
  bool may_deliver(const StreamKey& stream, uint32_t seq) const;
  // Hands a message over now, or keeps it until the tick that names it.
  void deliver_in_turn(const std::string& channel, const uint8_t* data, std::size_t size,
                       const StreamKey& stream, uint32_t seq);
  // Hands over the deferred messages that `heads` name (with `before_utime`, only those whose
  // time puts them before a tick at that utime: in_time), or with no heads those may_deliver()
  // lets go; each stream in its order, the rest in the order they came. `everything`: all.
  void release_deferred(const Heads* heads, std::optional<int64_t> before_utime = std::nullopt,
                        bool everything = false);
  // For ticks lost for good, whose heads are unknown: the clock's source publishes a tick's
  // sensor data before the tick (utime <= the tick's), the others what a tick made after it.
  bool in_time(const StreamKey& stream, const uint8_t* payload, std::size_t size, int64_t tick_utime) const;
  bool in_lockstep() const {
    return options_.follow_clock && !clock_source_ && clock_.started() &&
           clock_.mode() == ClockMode::kLockstep;
  }
  uint64_t clock_sender_ = 0;    // the clock's source (SIM_CLOCK's signer)
  double last_clock_wall_ = -1;  // the last SIM_CLOCK heard (a new tick or a resent one)
  struct AckHeads {
    int64_t sender = 0;
    std::vector<std::pair<int32_t, int32_t>> heads;  // (tag, seq)
  };
  std::map<std::string, AckHeads> ack_heads_;  // clock source: each node's latest ack
  semx::clock_t sent_clock_{};                 // clock source: the last new tick, with its heads
  int64_t sent_clock_tick_ = -1;
  bool clock_source_ = false;
  bool from_log_ = false;                // file:// provider: a log played back (on_signed_message)
  std::optional<uint64_t> log_session_;  // the one set read from it
  bool in_publish_clock_ = false;
  std::vector<std::function<void(int64_t, int64_t)>> tick_handlers_;
  std::function<int64_t(int64_t)> quiet_until_fn_;
  std::vector<std::function<void()>> after_ack_;
  int64_t last_ack_utime_ = -1;
  // In realtime nothing acks a tick, so a reader that lost a stream's last message (a plan, a
  // status) would not know until the next one came, if ever: every node tells the clock its
  // heads in an ack this often (wall seconds), and the ticks pass them on.
  static constexpr double kRealtimeHeadsPeriodS = 0.1;
  double last_heads_ack_wall_ = -1;
  int64_t quiet_until_ = 0;  // the promise sent with the last ack
  int64_t tick_period_us_ = 0;
  bool in_tick_ = false;
  int64_t early_publishes_ = 0;
  int64_t non_finite_publishes_ = 0;
  SimClock clock_;
  NodeState state_ = NodeState::kStarting;
  std::string detail_;
  NodeCounters counters_;
  std::map<std::string, ChannelCounters> incoming_;
  std::map<std::string, ChannelCounters> outgoing_;
  std::chrono::steady_clock::time_point next_status_;
  ParentWatch parent_watch_;       // stops the node once the launcher that started it is gone
  std::size_t announcements_ = 0;  // statuses sent so far, up to the announce delays' count
  std::atomic<bool> stop_{false};
};

// ---- templates ----

struct Node::Subscription {
  virtual ~Subscription() = default;
  bool finite_only = true;  // see judges_non_finite()
  // Returns kMalformed with `why` set when the bytes are not a usable message.
  virtual Outcome deliver(const uint8_t* data, std::size_t size, std::string& why) = 0;
};

template <class T>
struct Node::TypedSubscription : Node::Subscription {
  const LcmStruct* type;
  std::function<void(const T&)> handler;
  std::function<bool(const T&)> accept;

  Outcome deliver(const uint8_t* data, std::size_t size, std::string& why) override {
    const WireError e = validate_wire(LcmSchema::semx(), *type, T::getHash(), data, size, finite_only);
    if (e != WireError::kNone) {
      why = to_string(e);
      return Outcome::kMalformed;
    }
    T msg;
    try {
      if (msg.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) {
        why = "decoder rejected";
        return Outcome::kMalformed;
      }
      if (accept && !accept(msg)) {
        why = "content rejected";
        return Outcome::kMalformed;
      }
    } catch (const std::exception& ex) {
      why = std::string("decoder threw: ") + ex.what();
      return Outcome::kMalformed;
    }
    try {
      handler(msg);
    } catch (const std::exception& ex) {
      why = ex.what();
      return Outcome::kHandlerError;
    } catch (...) {
      why = "unknown exception";
      return Outcome::kHandlerError;
    }
    return Outcome::kDelivered;
  }
};

template <class T>
void Node::subscribe(const std::string& channel, std::function<void(const T&)> handler,
                     std::function<bool(const T&)> accept) {
  auto sub = std::make_unique<TypedSubscription<T>>();
  sub->type = &schema_of(T::getTypeName());
  sub->handler = std::move(handler);
  sub->accept = std::move(accept);
  ensure_lcm_subscription(channel);
  subs_[channel].push_back(std::move(sub));
}

template <class T>
bool Node::publish(const std::string& channel, const T& msg) {
  if constexpr (std::is_same_v<T, semx::clock_t>) {
    if (!in_publish_clock_) return publish_clock(channel, msg);
  }
  const int size = msg.getEncodedSize();
  if (size < 0) return false;
  encode_buffer_.reserve(static_cast<std::size_t>(size) + kAuthTrailerBytes);
  encode_buffer_.resize(static_cast<std::size_t>(size));
  if (msg.encode(encode_buffer_.data(), 0, size) != size) {
    auto& c = outgoing_[channel];
    c.outgoing = true;
    ++c.dropped;
    ++counters_.dropped;
    return false;
  }
  // Every receiver drops a message with a NaN or inf in it: say so where the bug is.
  if (validate_wire(LcmSchema::semx(), schema_of(T::getTypeName()), T::getHash(), encode_buffer_.data(),
                    encode_buffer_.size(), true) == WireError::kNonFinite) {
    note_non_finite_publish(channel);
  }
  return send_signed(channel, encode_buffer_);
}

}  // namespace semx::runtime
