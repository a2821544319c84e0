#include "semx/runtime/node.hpp"

#include <poll.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_datagram.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/udpm_sender.hpp"

namespace semx::runtime {

namespace {

std::atomic<bool> g_shutdown{false};

extern "C" void on_signal(int) { g_shutdown.store(true); }

int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t rss_kb() {
  std::ifstream statm("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  if (!(statm >> pages_total >> pages_resident)) return 0;
  return pages_resident * (sysconf(_SC_PAGESIZE) / 1024);
}

double cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Logs the 1st..5th, 10th, 100th, ... occurrence: a flood of bad messages must not become a
// flood of log lines, but the first ones and the scale are worth seeing.
bool worth_logging(int64_t n) {
  if (n <= 5) return true;
  while (n % 10 == 0) n /= 10;
  return n == 1;
}

// Channels whose messages are numbered for resending: all but the clock's own protocol (a lost
// tick or ack is sent again by the clock) and the heartbeat.
bool tracked(const std::string& channel) {
  return channel != channels::SIM_CLOCK && channel != channels::SIM_ACK && channel != channels::NODE_STATUS &&
         channel != channels::SIM_RESEND;
}

// In lockstep a gap costs only wall time, so it is waited for long (and a recorder wants every
// message); in realtime a message that comes much later is old news.
constexpr double kGiveUpLockstepS = 10.0, kGiveUpRealtimeS = 0.5;
// With no SIM_CLOCK for this long (the clock resends its tick every 50 ms while it waits), the
// clock is gone: messages waiting for a tick are handed over (a mapper's last request).
constexpr double kClockGoneS = 3.0;
// LOCKSTEP ticks lost for good that a node still handles when the next one comes (beyond: it
// joined late or the clock jumped, and they are not this node's to make up).
constexpr int64_t kMaxMissedTicks = 100;

AuthKey node_key(const NodeOptions& o) {
  try {
    return AuthKey::resolve(o.auth_key_file);
  } catch (const std::exception& e) {
    throw NodeError(o.name + ": " + e.what());
  }
}

}  // namespace

const char* to_string(NodeState s) {
  switch (s) {
    case NodeState::kStarting:
      return "starting";
    case NodeState::kRunning:
      return "running";
    case NodeState::kDegraded:
      return "degraded";
    case NodeState::kDone:
      return "done";
    case NodeState::kStopping:
      return "stopping";
    case NodeState::kFailed:
      return "failed";
  }
  return "?";
}

void install_shutdown_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // A reader that went away must not kill a process writing its log lines to a pipe.
  std::signal(SIGPIPE, SIG_IGN);
}

bool shutdown_requested() { return g_shutdown.load(); }
void request_shutdown() { g_shutdown.store(true); }

Node::Node(NodeOptions options)
    : options_(std::move(options)),
      key_(node_key(options_)),
      signer_(key_),
      verifier_(key_),
      inbox_(signer_.sender(), Inbox::Options{0.05, kGiveUpLockstepS, 64u << 20}),
      clock_(options_.lockstep) {
  if (options_.name.empty()) throw NodeError("a node needs a name");
  options_.lcm_url = resolve_lcm_url(options_.lcm_url);
  from_log_ = options_.lcm_url.rfind("file://", 0) == 0;
  const char* transport = std::getenv("SEMX_LCM_TRANSPORT");
  if (!(transport && std::string(transport) == "liblcm")) udpm_ = parse_udpm_url(options_.lcm_url);
  if (udpm_) {
    try {
      sender_ = std::make_unique<UdpmSender>(*udpm_);
    } catch (const std::exception& e) {
      throw NodeError("cannot open LCM provider '" + options_.lcm_url + "': " + e.what());
    }
  } else {
    lcm_ = std::make_unique<lcm::LCM>(options_.lcm_url);
    if (!lcm_->good()) throw NodeError("cannot open LCM provider '" + options_.lcm_url + "'");
  }
  if (options_.follow_clock) {
    subscribe<semx::clock_t>(
        channels::SIM_CLOCK, [this](const semx::clock_t& m) { on_clock_message(m); },
        [](const semx::clock_t& m) {
          return m.tick >= 0 && m.utime >= 0 &&
                 (m.mode == semx::clock_t::REALTIME || m.mode == semx::clock_t::LOCKSTEP);
        });
  }
  subscribe<semx::resend_t>(
      channels::SIM_RESEND, [this](const semx::resend_t& r) { on_resend_request(r); },
      [](const semx::resend_t& r) { return r.first_seq >= 1 && r.last_seq >= r.first_seq; });
  // A node started into a running set (respawned: SEMX_RESTART > 0, or an observer) owes
  // nothing to what was sent before it came.
  const char* restart = std::getenv("SEMX_RESTART");
  inbox_.set_from_start(!options_.observer && !(restart && std::atoi(restart) > 0));
  next_status_ = std::chrono::steady_clock::now();
}

Node::~Node() = default;

const LcmStruct& Node::schema_of(const char* type_name) const {
  const LcmStruct* s = LcmSchema::semx().find(std::string("semx.") + type_name);
  if (!s) throw NodeError(std::string("no .lcm layout for type ") + type_name);
  return *s;
}

void Node::ensure_lcm_subscription(const std::string& channel) {
  if (subs_.count(channel)) return;
  // LCM treats the name as a regex; semx channel names are plain [A-Z0-9_].
  for (char c : channel) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      throw NodeError("channel name '" + channel + "' must be letters, digits and '_'");
    }
  }
  subs_[channel];
  inbox_.reads(channel_tag(channel));
  if (udpm_) {
    receive_channels_.push_back(channel);
    update_receiver();
  } else {
    lcm_->subscribe(channel, &Node::on_lcm_message, this);
  }
}

void Node::update_receiver() {
  try {
    if (!receiver_) {
      receiver_ = std::make_unique<UdpmReceiver>(*udpm_, options_.max_message_bytes);
      if (options_.sign) receiver_->report_tails(kAuthTrailerBytes);
      if (const char* rate = std::getenv("SEMX_TEST_DROP_RATE"); rate && *rate) {
        // A lossy bus for tests and experiments: this node loses that share of its datagrams.
        const char* seed = std::getenv("SEMX_TEST_DROP_SEED");
        receiver_->drop_for_test(std::atof(rate), std::hash<std::string>{}(options_.name) ^
                                                      (seed ? std::strtoull(seed, nullptr, 10) : 0));
      }
      if (const char* ms = std::getenv("SEMX_TEST_JITTER_MS"); ms && *ms) {
        // A bus with jitter: this node's datagrams each come up to that late, out of order.
        const char* seed = std::getenv("SEMX_TEST_DROP_SEED");
        receiver_->delay_for_test(std::atof(ms) / 1000.0, std::hash<std::string>{}(options_.name) ^
                                                              (seed ? std::strtoull(seed, nullptr, 10) : 0) ^
                                                              0x6a09e667u);
      }
      if (receiver_->granted_recv_buf() < receiver_->requested_recv_buf()) {
        throw NodeError(
            "the LCM URL asks for a " + std::to_string(receiver_->requested_recv_buf()) +
            "-byte receive buffer and the kernel grants " + std::to_string(receiver_->granted_recv_buf()) +
            " (net.core.rmem_max): bursts of camera frames would be lost. Raise it (as root: sysctl "
            "-w net.core.rmem_max=" +
            std::to_string(receiver_->requested_recv_buf()) +
            "), or ask for less with recv_buf_size= in the URL");
      }
    }
    std::vector<std::string> refused;
    for (const auto& c : never_wanted_)
      if (!subs_.count(c)) refused.push_back(c);
    receiver_->filter(receive_channels_, !raw_handlers_.empty(), refused);
  } catch (const std::exception& e) {
    throw NodeError(options_.name + ": " + e.what());
  }
}

void Node::skip_unless(const std::string& channel, std::function<bool(int64_t utime)> wanted) {
  skip_filters_[channel] = std::move(wanted);
}

void Node::subscribe_raw(const std::string& regex, RawHandler handler, bool with_trailer) {
  try {
    raw_handlers_.push_back({ChannelPattern(regex), std::move(handler), with_trailer});
  } catch (const std::invalid_argument& e) {
    throw NodeError(e.what());
  }
  if (udpm_) {
    update_receiver();  // the kernel filter cannot match patterns: everything passes
  } else if (raw_handlers_.size() == 1) {
    lcm_->subscribe(".*", &Node::on_lcm_raw_message, this);
  }
}

void Node::never_wanted(std::vector<std::string> channels) {
  never_wanted_ = std::move(channels);
  if (receiver_) update_receiver();
}

void Node::on_lcm_raw_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // liblcm calls the typed subscription of a channel first; a channel without one reaches here
  // only, and is checked here.
  if (subs_.count(channel)) return;
  on_signed_message(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
}

void Node::on_raw_message(const std::string& channel, const uint8_t* data, std::size_t size,
                          std::size_t payload) {
  // Raw subscribers see the bytes as they came; they count nothing as malformed themselves.
  for (auto& raw : raw_handlers_) {
    if (!raw.pattern.matches(channel)) continue;
    try {
      raw.handler(channel, data, raw.with_trailer ? size : payload);
    } catch (const std::exception& e) {
      note_handler_error(channel, e.what());
    }
  }
}

void Node::on_lcm_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  on_signed_message(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
}

void Node::on_signed_message(const std::string& channel, const uint8_t* data, std::size_t size) {
  if (from_log_) {
    // A log the user chose to play (file://): nobody else writes into it, and logs from before
    // messages were signed have no trailers. Only one set's messages are read, though: a stock
    // lcm-logger may have recorded two sets at once.
    const auto t = read_trailer(data, size);
    if (t) {
      if (!log_session_) log_session_ = t->session;
      if (t->session != *log_session_) {
        note_refused(channel, AuthVerdict::kForeign, *t);
        return;
      }
    }
    dispatch(channel, data, size, t ? size - kAuthTrailerBytes : size);
    return;
  }
  AuthTrailer trailer;
  const AuthVerdict verdict = verifier_.verify(channel, data, size, &trailer);
  if (verdict == AuthVerdict::kReplayed && tracked(channel) && trailer.seq != 0) {
    // A publisher's resend is the message as first sent, counter and all: a duplicate for a
    // reader that had it, the message itself for one that lost it.
    switch (inbox_.resent({trailer.sender, channel_tag(channel)}, trailer.seq)) {
      case Inbox::Resent::kDuplicate:
        return;
      case Inbox::Resent::kAwaited:
        if (verifier_.authentic(channel, data, size)) break;
        note_refused(channel, AuthVerdict::kForged, trailer);
        return;
      case Inbox::Resent::kUnknown:
        note_refused(channel, verdict, trailer);
        return;
    }
  } else if (verdict != AuthVerdict::kOk) {
    note_refused(channel, verdict, trailer);
    return;
  }
  if (channel == channels::SIM_CLOCK) clock_sender_ = trailer.sender;
  const bool in_order = tracked(channel) && trailer.seq != 0;  // seq 0: an observer's (send_signed)
  if (in_order) {
    const StreamKey stream{trailer.sender, channel_tag(channel)};
    switch (inbox_.arrive(stream, trailer.seq, channel, data, size, monotonic_s())) {
      case Inbox::Arrival::kDuplicate:
      case Inbox::Arrival::kHeld:
        return;
      case Inbox::Arrival::kDeliver:
        break;
    }
  }
  if (!in_order) {
    dispatch(channel, data, size, size - kAuthTrailerBytes);
    return;
  }
  deliver_in_turn(channel, data, size, {trailer.sender, channel_tag(channel)}, trailer.seq);
  // Held messages a gap kept back, now in their publisher's order.
  deliver_ready();
}

bool Node::named(const Heads& heads, const StreamKey& stream, uint32_t seq) {
  const auto it = heads.find(stream);
  return it != heads.end() && seq <= it->second;
}

bool Node::may_deliver(const StreamKey& stream, uint32_t seq) const {
  if (stream.sender == signer_.sender()) return true;
  if (!held_ticks_.empty()) return false;  // all of it comes out in its order once the tick is complete
  // An observer changes nothing of the run: a recorder writes what comes when it comes, up to
  // the end (no tick comes after the last one to hand the last messages over).
  if (!in_lockstep() || options_.observer || !acking_senders_.count(stream.sender)) return true;
  return named(tick_heads_, stream, seq);
}

bool Node::in_time(const StreamKey& stream, const uint8_t* payload, std::size_t size,
                   int64_t tick_utime) const {
  if (size < 16) return true;
  uint64_t u = 0;  // big-endian int64 right after the 8-byte fingerprint: every semx type's utime
  for (int i = 8; i < 16; ++i) u = (u << 8) | payload[i];
  const auto utime = static_cast<int64_t>(u);
  return stream.sender == clock_sender_ ? utime <= tick_utime : utime < tick_utime;
}

void Node::deliver_in_turn(const std::string& channel, const uint8_t* data, std::size_t size,
                           const StreamKey& stream, uint32_t seq) {
  bool now = may_deliver(stream, seq);
  for (auto it = deferred_.begin(); now && it != deferred_.end(); ++it) {
    if (!(it->stream < stream) && !(stream < it->stream)) now = false;  // after its stream's waiting ones
  }
  if (now) {
    dispatch(channel, data, size, size - kAuthTrailerBytes);
    return;
  }
  deferred_.push_back({channel, std::vector<uint8_t>(data, data + size), stream, seq});
}

void Node::release_deferred(const Heads* heads, std::optional<int64_t> before_utime, bool everything) {
  if (deferred_.empty()) return;
  std::deque<Inbox::Ready> waiting;
  waiting.swap(deferred_);
  std::set<StreamKey> blocked;
  // The other nodes' answers to the last tick first, then the clock's source's data for the next
  // one: the clock's source sent its data only once their acks came.
  for (const bool from_clock : {false, true}) {
    std::deque<Inbox::Ready> rest;
    for (auto& d : waiting) {
      const std::size_t payload = d.bytes.size() - kAuthTrailerBytes;
      bool go = (d.stream.sender == clock_sender_) == from_clock;
      if (go && !everything) go = heads ? named(*heads, d.stream, d.seq) : may_deliver(d.stream, d.seq);
      if (go && !everything && before_utime) go = in_time(d.stream, d.bytes.data(), payload, *before_utime);
      if (go && !blocked.count(d.stream)) {
        dispatch(d.channel, d.bytes.data(), d.bytes.size(), payload);
      } else {
        if (!go && (d.stream.sender == clock_sender_) == from_clock) blocked.insert(d.stream);
        rest.push_back(std::move(d));
      }
    }
    waiting.swap(rest);
  }
  // What stays, in the order it came, after anything deferred meanwhile.
  for (auto& d : deferred_) waiting.push_back(std::move(d));
  deferred_.swap(waiting);
}

void Node::deliver_ready() {
  Inbox::Ready r;
  while (inbox_.ready(&r)) deliver_in_turn(r.channel, r.bytes.data(), r.bytes.size(), r.stream, r.seq);
}

void Node::dispatch(const std::string& channel, const uint8_t* data, std::size_t size, std::size_t payload) {
  if (subs_.count(channel)) on_message(channel, data, payload);
  if (!raw_handlers_.empty()) on_raw_message(channel, data, size, payload);
}

void Node::on_resend_request(const semx::resend_t& r) {
  if (static_cast<uint64_t>(r.sender) != signer_.sender() || (!sender_ && !lcm_)) return;
  // A bounded answer: a request cannot make a node send its whole history in one go.
  const uint32_t first = static_cast<uint32_t>(r.first_seq);
  const uint32_t last = std::min<uint32_t>(static_cast<uint32_t>(r.last_seq), first + 255);
  for (uint32_t seq = first; seq <= last; ++seq) {
    const std::string* channel = nullptr;
    uint32_t wire_seqno = 0;
    const std::vector<uint8_t>* kept =
        history_.find(static_cast<uint32_t>(r.channel_tag), seq, &channel, &wire_seqno);
    if (!kept) continue;
    bool sent = false;
    if (sender_) {
      // The bytes as first sent, under their first seqno: a reader that lost one fragment of a
      // 1 MB frame needs only that fragment from this copy (lcm_datagram.hpp, SXR3).
      sent = sender_->publish_again(*channel, kept->data(), kept->size(), wire_seqno);
    } else {
      resend_buffer_.assign(kept->begin(), kept->end() - static_cast<std::ptrdiff_t>(kAuthTrailerBytes));
      signer_.sign_as(*channel, resend_buffer_, seq);
      sent = lcm_->publish(*channel, resend_buffer_.data(),
                           static_cast<unsigned int>(resend_buffer_.size())) == 0;
    }
    if (sent) ++counters_.resent;
  }
}

std::vector<std::pair<int32_t, int32_t>> Node::own_heads() const {
  std::vector<std::pair<int32_t, int32_t>> out;
  for (const auto& [channel, seq] : signer_.heads()) {
    if (tracked(channel))
      out.emplace_back(static_cast<int32_t>(channel_tag(channel)), static_cast<int32_t>(seq));
  }
  return out;
}

bool Node::publish_clock(const std::string& channel, const semx::clock_t& msg) {
  if (!clock_source_ && channel == channels::SIM_CLOCK) {
    clock_source_ = true;
    subscribe<semx::ack_t>(channels::SIM_ACK, [this](const semx::ack_t& a) {
      AckHeads& h = ack_heads_[a.node];
      h.sender = a.sender;
      h.heads.clear();
      std::vector<StreamHead> named;
      for (int i = 0; i < a.num_heads; ++i) {
        h.heads.emplace_back(a.head_tag[i], a.head_seq[i]);
        named.push_back({{static_cast<uint64_t>(a.sender), static_cast<uint32_t>(a.head_tag[i])},
                         static_cast<uint32_t>(a.head_seq[i])});
      }
      // What the clock itself reads (the controller's commands) must be held before the next tick.
      inbox_.tick(named, monotonic_s());
    });
  }
  semx::clock_t m = msg;
  if (channel == channels::SIM_CLOCK && msg.tick == sent_clock_tick_) {
    // The same tick again: the same heads. Acks that came since name what the nodes sent while
    // handling this tick, which comes after it; a reader that lost the tick would otherwise take
    // those messages as coming before it.
    m.num_heads = sent_clock_.num_heads;
    m.head_sender = sent_clock_.head_sender;
    m.head_tag = sent_clock_.head_tag;
    m.head_seq = sent_clock_.head_seq;
  } else if (channel == channels::SIM_CLOCK) {
    m.head_sender.clear();
    m.head_tag.clear();
    m.head_seq.clear();
    const auto add = [&m](int64_t sender, const std::vector<std::pair<int32_t, int32_t>>& heads) {
      for (const auto& [tag, seq] : heads) {
        m.head_sender.push_back(sender);
        m.head_tag.push_back(tag);
        m.head_seq.push_back(seq);
      }
    };
    add(static_cast<int64_t>(signer_.sender()), own_heads());
    for (const auto& [node, h] : ack_heads_) add(h.sender, h.heads);
    m.num_heads = static_cast<int16_t>(std::min<std::size_t>(m.head_seq.size(), 32767));
    m.head_sender.resize(static_cast<std::size_t>(m.num_heads));
    m.head_tag.resize(static_cast<std::size_t>(m.num_heads));
    m.head_seq.resize(static_cast<std::size_t>(m.num_heads));
    sent_clock_ = m;
    sent_clock_tick_ = m.tick;
  }
  in_publish_clock_ = true;
  const bool ok = publish(channel, m);
  in_publish_clock_ = false;
  return ok;
}

void Node::service_delivery() {
  const double now = monotonic_s();
  inbox_.set_give_up_s(clock_.started() && clock_.mode() == ClockMode::kRealtime ? kGiveUpRealtimeS
                                                                                 : kGiveUpLockstepS);
  for (const ResendRequest& q : inbox_.requests(now)) {
    semx::resend_t r;
    r.utime = clock_.now_utime();
    r.node = options_.name;
    r.sender = static_cast<int64_t>(q.stream.sender);
    r.channel_tag = static_cast<int32_t>(q.stream.tag);
    r.first_seq = static_cast<int32_t>(q.first);
    r.last_seq = static_cast<int32_t>(q.last);
    publish(channels::SIM_RESEND, r);
  }
  const auto lost = inbox_.give_up(now);
  for (const ResendRequest& l : lost) {
    counters_.lost += l.last - l.first + 1;
    std::string channel = "tag " + std::to_string(l.stream.tag);
    for (const auto& [name, subs] : subs_)
      if (channel_tag(name) == l.stream.tag) channel = name;
    std::cerr << options_.name << ": gave up on " << channel << " messages " << l.first << ".." << l.last
              << " of sender " << std::hex << l.stream.sender << std::dec << " (" << counters_.lost
              << " lost so far): this run is not the one a lossless bus gives\n";
  }
  if (!lost.empty()) deliver_ready();
  counters_.recovered = inbox_.counters().recovered;
  while (!held_ticks_.empty() && inbox_.complete()) {
    // What the tick names, then the tick; what comes after it waits for the tick that names it.
    const HeldTick tick = held_ticks_.front();
    handle_tick_in_turn(tick.msg, tick.heads, true);
  }
  if (held_ticks_.empty() && !deferred_.empty() && last_clock_wall_ >= 0 &&
      now - last_clock_wall_ >= kClockGoneS)
    release_deferred(nullptr, std::nullopt, true);
}

void Node::note_refused(const std::string& channel, AuthVerdict verdict, const AuthTrailer& trailer) {
  auto& c = incoming_[channel];
  if (verdict == AuthVerdict::kForeign) {
    ++c.foreign;
    ++counters_.foreign;
    if (!options_.quiet && worth_logging(counters_.foreign)) {
      std::cerr << options_.name << ": ignored a message of another set (session " << std::hex
                << trailer.session << std::dec << ") on " << channel << " (" << counters_.foreign
                << " so far): two sets share this bus\n";
    }
    return;
  }
  ++c.refused;
  ++counters_.refused;
  if (!options_.quiet && worth_logging(counters_.refused)) {
    std::cerr << options_.name << ": refused a " << to_string(verdict) << " message on " << channel << " ("
              << counters_.refused << " so far)\n";
  }
}

void Node::on_message(const std::string& channel, const uint8_t* data, std::size_t size) {
  auto& c = incoming_[channel];
  ++c.messages;
  c.bytes += static_cast<int64_t>(size);
  ++counters_.received;
  if (size > options_.max_message_bytes) {
    ++c.dropped;
    ++counters_.dropped;
    if (!options_.quiet && worth_logging(c.dropped)) {
      std::cerr << options_.name << ": dropped " << size << "-byte message on " << channel << " (limit "
                << options_.max_message_bytes << "; " << c.dropped << " so far)\n";
    }
    return;
  }
  auto it = subs_.find(channel);
  if (it == subs_.end()) return;
  if (!skip_filters_.empty() && size >= 16) {
    const auto f = skip_filters_.find(channel);
    if (f != skip_filters_.end()) {
      uint64_t utime = 0;  // big-endian int64 right after the 8-byte fingerprint
      for (int i = 8; i < 16; ++i) utime = (utime << 8) | data[i];
      if (!f->second(static_cast<int64_t>(utime))) {
        ++c.skipped;
        return;
      }
    }
  }
  bool malformed = false;
  for (auto& sub : it->second) {
    std::string why;
    switch (sub->deliver(data, size, why)) {
      case Outcome::kDelivered:
        break;
      case Outcome::kMalformed:
        if (!malformed) note_malformed(channel, why, size);
        malformed = true;
        break;
      case Outcome::kHandlerError:
        note_handler_error(channel, why.c_str());
        break;
    }
  }
}

void Node::note_malformed(const std::string& channel, const std::string& why, std::size_t size) {
  auto& c = incoming_[channel];
  ++c.malformed;
  ++counters_.malformed;
  if (!options_.quiet && worth_logging(c.malformed)) {
    std::cerr << options_.name << ": dropped malformed message on " << channel << ": " << why << " (" << size
              << " bytes; " << c.malformed << " so far)\n";
  }
}

void Node::note_handler_error(const std::string& channel, const char* what) {
  ++counters_.handler_errors;
  if (!options_.quiet && worth_logging(counters_.handler_errors)) {
    std::cerr << options_.name << ": handler for " << channel << " failed: " << what << " ("
              << counters_.handler_errors << " so far)\n";
  }
}

void Node::judges_non_finite(const std::string& channel) {
  for (auto& sub : subs_[channel]) sub->finite_only = false;
}

void Node::note_non_finite_publish(const std::string& channel) {
  ++non_finite_publishes_;
  if (worth_logging(non_finite_publishes_)) {
    std::cerr << options_.name << ": published a " << channel << " message with a NaN or infinite value ("
              << non_finite_publishes_ << " so far): every semx node drops it\n";
  }
}

bool Node::publish_raw(const std::string& channel, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  publish_buffer_.reserve(size + kAuthTrailerBytes);
  publish_buffer_.assign(bytes, bytes + size);
  return send_signed(channel, publish_buffer_);
}

bool Node::send_signed(const std::string& channel, std::vector<uint8_t>& bytes) {
  AuthTrailer trailer;
  if (options_.sign) {
    if (channel.empty() || channel.size() > kLcmMaxChannel) return false;
    // An observer's messages (its heartbeat, its resend requests) are not part of any run:
    // seq 0 tells readers not to wait for, ask for or count them, so an observer that ends or
    // loses datagrams never holds a lockstep tick or makes a run invalid.
    trailer = options_.observer ? signer_.sign_as(channel, bytes, 0) : signer_.sign(channel, bytes);
  }
  const uint8_t* data = bytes.data();
  const std::size_t size = bytes.size();
  if (quiet_until_ > 0 && !may_publish() && tracked(channel)) {
    ++early_publishes_;
    if (worth_logging(early_publishes_)) {
      std::cerr << options_.name << ": published " << channel << " at utime " << clock_.now_utime()
                << ", before its promised quiet_until " << quiet_until_ << " (" << early_publishes_
                << " so far): this lockstep run may not repeat\n";
    }
  }
  auto& c = outgoing_[channel];
  c.outgoing = true;
  uint32_t wire_seqno = 0;
  const bool sent = sender_ ? sender_->publish(channel, data, size, &wire_seqno)
                            : lcm_->publish(channel, data, static_cast<unsigned int>(size)) == 0;
  if (!sent) {
    ++c.dropped;
    ++counters_.dropped;
    // Kept all the same: its sequence number is spent, and a reader will ask for it.
    if (options_.sign && tracked(channel) && trailer.seq != 0)
      bytes = history_.keep(channel, channel_tag(channel), trailer.seq, std::move(bytes), wire_seqno);
    return false;
  }
  ++c.messages;
  // The message's own bytes, as readers count them (the trailer is transport).
  c.bytes += static_cast<int64_t>(options_.sign ? size - kAuthTrailerBytes : size);
  ++counters_.sent;
  // Kept for a reader that lost it; the buffer handed back is reused by the next message.
  if (options_.sign && tracked(channel) && trailer.seq != 0) {
    bytes = history_.keep(channel, channel_tag(channel), trailer.seq, std::move(bytes), wire_seqno);
  }
  return true;
}

void Node::on_clock_message(const semx::clock_t& msg) {
  last_clock_wall_ = monotonic_s();
  // A tick already waiting (the clock sends it again until acked) changes nothing.
  for (const auto& h : held_ticks_) {
    if (h.msg.tick == msg.tick) return;
  }
  std::vector<StreamHead> heads;
  heads.reserve(static_cast<std::size_t>(msg.num_heads));
  for (int i = 0; i < msg.num_heads; ++i) {
    heads.push_back({{static_cast<uint64_t>(msg.head_sender[i]), static_cast<uint32_t>(msg.head_tag[i])},
                     static_cast<uint32_t>(msg.head_seq[i])});
  }
  const bool complete = inbox_.tick(heads, monotonic_s());
  HeldTick held{msg, {}};
  for (const StreamHead& h : heads) held.heads[h.stream] = std::max(held.heads[h.stream], h.seq);
  // In realtime a tick is not held for what it names: what is missing is asked for and handed
  // over when it comes, while time goes on (a controller held for a lost ESDF would not steer).
  if (msg.mode != semx::clock_t::REALTIME && (!complete || !held_ticks_.empty())) {
    held_ticks_.push_back(std::move(held));
    service_delivery();
    return;
  }
  handle_tick_in_turn(msg, held.heads, false);
}

void Node::handle_tick_in_turn(const semx::clock_t& msg, const Heads& heads, bool held) {
  const int64_t last = clock_.last_tick();
  if (msg.mode == semx::clock_t::LOCKSTEP && in_lockstep() && msg.period_us > 0 && msg.tick > last + 1 &&
      msg.tick - last <= kMaxMissedTicks) {
    // Ticks this node lost for good (the clock did not wait for it on them, so it did not send
    // them again): handled now, in turn, as a lossless bus gives them, with what their time puts
    // before them. Not acked: the clock went on.
    for (int64_t j = last + 1; j < msg.tick; ++j) {
      semx::clock_t missed = msg;
      missed.tick = j;
      missed.utime = msg.utime - (msg.tick - j) * msg.period_us;
      release_deferred(&heads, missed.utime);
      handle_tick(missed, false);
    }
  }
  release_deferred(&heads);
  if (held) held_ticks_.pop_front();
  for (const auto& [stream, seq] : heads) {
    uint32_t& h = tick_heads_[stream];
    h = std::max(h, seq);
    acking_senders_.insert(stream.sender);
  }
  handle_tick(msg, true);
  release_deferred(nullptr);
}

void Node::handle_tick(const semx::clock_t& msg, bool may_ack) {
  const auto decision = clock_.on_clock(msg.tick, msg.utime, static_cast<ClockMode>(msg.mode));
  if (decision.new_tick) {
    if (msg.tick > 0 && msg.utime > 0) tick_period_us_ = msg.utime / msg.tick;
    in_tick_ = true;
    for (auto& fn : tick_handlers_) fn(msg.tick, msg.utime);
    in_tick_ = false;
  }
  const bool skip_ack = decision.new_tick && !decision.reset && quiet_until_ > msg.utime &&
                        last_ack_utime_ >= 0 && msg.utime >= last_ack_utime_ &&
                        msg.utime - last_ack_utime_ < kAckIntervalUs;
  const bool heads_ack =
      !decision.ack && may_ack && msg.mode == semx::clock_t::REALTIME && !options_.observer &&
      options_.sign && monotonic_s() - last_heads_ack_wall_ >= kRealtimeHeadsPeriodS && !own_heads().empty();
  if ((decision.ack && may_ack && !skip_ack) || heads_ack) {
    if (heads_ack) last_heads_ack_wall_ = monotonic_s();
    semx::ack_t ack{};
    ack.utime = msg.utime;
    ack.node = options_.name;
    ack.tick = msg.tick;
    ack.quiet_until = !heads_ack && quiet_until_fn_ ? quiet_until_fn_(msg.utime) : 0;
    ack.sender = static_cast<int64_t>(signer_.sender());
    for (const auto& [tag, seq] : own_heads()) {
      ack.head_tag.push_back(tag);
      ack.head_seq.push_back(seq);
    }
    ack.num_heads = static_cast<int16_t>(ack.head_seq.size());
    publish(channels::SIM_ACK, ack);
    if (!heads_ack) {
      quiet_until_ = ack.quiet_until;
      last_ack_utime_ = msg.utime;
    }
  }
  std::vector<std::function<void()>> work;
  work.swap(after_ack_);
  for (auto& fn : work) fn();
}

bool Node::may_publish() const {
  // A tick handler's output goes out before this tick's ack; a message handler's before the
  // next tick's: either is on time when the clock waits for that ack.
  const int64_t at = clock_.now_utime() + (in_tick_ ? 0 : tick_period_us_);
  return at >= quiet_until_;
}

void Node::set_time(int64_t utime, int64_t tick, ClockMode mode) { clock_.on_clock(tick, utime, mode); }

void Node::set_state(NodeState state, const std::string& detail) {
  if (state == state_ && detail == detail_) return;
  state_ = state;
  detail_ = detail;
  publish_status();
}

semx::node_status_t Node::status() const {
  semx::node_status_t s;
  s.utime = clock_.now_utime();
  s.wall_utime = wall_utime();
  s.node = options_.name;
  s.pid = static_cast<int32_t>(getpid());
  s.restarts = options_.restarts;
  s.state = static_cast<int8_t>(state_);
  s.detail = detail_;
  s.received = counters_.received;
  s.sent = counters_.sent;
  s.dropped = counters_.dropped;
  s.malformed = counters_.malformed;
  s.handler_errors = counters_.handler_errors;
  s.foreign = counters_.foreign;
  s.refused = counters_.refused;
  s.lost = counters_.lost;
  s.observer = options_.observer;
  s.recovered = counters_.recovered;
  s.cpu_s = cpu_seconds();
  s.rss_kb = rss_kb();
  s.lockstep = options_.lockstep;
  s.last_tick = clock_.last_tick();
  for (const auto* dir : {&incoming_, &outgoing_}) {
    for (const auto& [channel, c] : *dir) {
      semx::channel_stats_t cs;
      cs.channel = channel;
      cs.outgoing = c.outgoing;
      cs.messages = c.messages;
      cs.malformed = c.malformed;
      cs.dropped = c.dropped;
      cs.bytes = c.bytes;
      s.channels.push_back(cs);
    }
  }
  s.num_channels = static_cast<int32_t>(s.channels.size());
  return s;
}

void Node::publish_status() {
  // Counted before building, so the status a reader sees includes the status being sent.
  const auto s = status();
  publish(channels::NODE_STATUS, s);
  double next_s = options_.status_period_s;
  if (options_.announce && announcements_ < std::size(kAnnounceDelaysS))
    next_s = std::min(next_s, kAnnounceDelaysS[announcements_]);
  ++announcements_;
  next_status_ =
      std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<int64_t>(next_s * 1e6));
}

int Node::spin_once(int timeout_ms) {
  const auto now = std::chrono::steady_clock::now();
  if (now >= next_status_) {
    if (!stop_ && parent_watch_.parent_gone()) {
      std::cerr << options_.name << ": the launcher that started it (pid " << parent_watch_.parent()
                << ") is gone: stopping\n";
      stop_ = true;
    }
    publish_status();
  }
  const auto until_status = std::chrono::duration_cast<std::chrono::milliseconds>(next_status_ - now).count();
  const int wait = static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(timeout_ms, until_status)));
  if (udpm_) {
    const int got = receive_once(wait);
    service_delivery();
    return got;
  }
  const int rc = lcm_->handleTimeout(wait);
  service_delivery();
  if (rc < 0) return shutdown_requested() ? 0 : -1;  // a signal interrupting the wait is not a failure
  return rc > 0 ? 1 : 0;
}

int Node::receive_once(int wait_ms) {
  // One message per call, as liblcm's handle() gives: callers check their state between messages.
  if (!receiver_) {
    ::poll(nullptr, 0, wait_ms);  // nothing subscribed: nothing can arrive
    return 0;
  }
  LcmMessageView m;
  bool got = receiver_->next(&m);
  if (!got && wait_ms > 0 && receiver_->wait(wait_ms)) got = receiver_->next(&m);
  note_receiver_problems();
  LcmReassembler::Tail tail;
  while (receiver_->next_tail(&tail)) {
    // An incomplete message's trailer (unverified: it is only a hint) names its stream and seq,
    // so the node asks for it now instead of when a later message of the channel comes whole.
    const auto t = read_trailer(tail.bytes.data(), tail.bytes.size());
    if (!t || t->session != verifier_.session() || !verifier_.knows(t->sender) || !seqno_tagged(tail.seqno))
      continue;
    inbox_.hint({t->sender, (tail.seqno >> kSeqnoTagShift) & kSeqnoTagBits}, t->seq);
  }
  if (!got) return 0;
  // liblcm calls a channel's handlers in the order they subscribed; the typed subscription of a
  // channel comes before any pattern here (SIM_CLOCK is subscribed in the constructor).
  if (subs_.count(*m.channel) || !raw_handlers_.empty()) on_signed_message(*m.channel, m.data, m.size);
  return 1;
}

void Node::note_receiver_problems() {
  const ReassemblyCounters& now = receiver_->counters();
  const int64_t rejected = now.rejected - receiver_seen_.rejected;
  const int64_t incomplete = now.incomplete - receiver_seen_.incomplete;
  if (rejected == 0 && incomplete == 0) return;
  receiver_seen_ = now;
  counters_.malformed += rejected;
  counters_.dropped += incomplete;
  if (options_.quiet) return;
  if (rejected > 0 && worth_logging(now.rejected)) {
    std::cerr << options_.name << ": dropped a datagram that is not LCM's ("
              << to_string(receiver_->last_error()) << "; " << now.rejected << " so far)\n";
  }
  if (incomplete > 0 && worth_logging(now.incomplete)) {
    std::cerr << options_.name << ": dropped a message whose fragments did not all arrive (" << now.incomplete
              << " so far)\n";
  }
}

int Node::drain() {
  int n = 0;
  while (spin_once(0) > 0) ++n;
  return n;
}

int Node::run() {
  if (state_ == NodeState::kStarting) set_state(NodeState::kRunning);
  int rc = 0;
  while (!stopped()) {
    if (spin_once(100) < 0) {
      set_state(NodeState::kFailed, "LCM provider failed");
      rc = 1;
      break;
    }
  }
  if (rc == 0) set_state(NodeState::kStopping, shutdown_requested() ? "signal" : "stopped");
  return rc;
}

}  // namespace semx::runtime
