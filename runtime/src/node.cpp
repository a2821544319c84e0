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

#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_url.hpp"

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

Node::Node(NodeOptions options) : options_(std::move(options)), clock_(options_.lockstep) {
  if (options_.name.empty()) throw NodeError("a node needs a name");
  options_.lcm_url = resolve_lcm_url(options_.lcm_url);
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
  if (udpm_) {
    receive_channels_.push_back(channel);
    update_receiver();
  } else {
    lcm_->subscribe(channel, &Node::on_lcm_message, this);
  }
}

void Node::update_receiver() {
  try {
    if (!receiver_) receiver_ = std::make_unique<UdpmReceiver>(*udpm_, options_.max_message_bytes);
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

void Node::subscribe_raw(const std::string& regex, RawHandler handler) {
  try {
    raw_handlers_.push_back({ChannelPattern(regex), std::move(handler)});
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
  on_raw_message(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
}

void Node::on_raw_message(const std::string& channel, const uint8_t* data, std::size_t size) {
  // Raw subscribers see the bytes as they came; they count nothing as malformed themselves.
  for (auto& raw : raw_handlers_) {
    if (!raw.pattern.matches(channel)) continue;
    try {
      raw.handler(channel, data, size);
    } catch (const std::exception& e) {
      note_handler_error(channel, e.what());
    }
  }
}

void Node::on_lcm_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  on_message(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
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

bool Node::publish_raw(const std::string& channel, const void* data, std::size_t size) {
  if (quiet_until_ > 0 && !may_publish() && channel != channels::NODE_STATUS &&
      channel != channels::SIM_ACK) {
    ++early_publishes_;
    if (worth_logging(early_publishes_)) {
      std::cerr << options_.name << ": published " << channel << " at utime " << clock_.now_utime()
                << ", before its promised quiet_until " << quiet_until_ << " (" << early_publishes_
                << " so far): this lockstep run may not repeat\n";
    }
  }
  auto& c = outgoing_[channel];
  c.outgoing = true;
  const bool sent = sender_ ? sender_->publish(channel, static_cast<const uint8_t*>(data), size)
                            : lcm_->publish(channel, data, static_cast<unsigned int>(size)) == 0;
  if (!sent) {
    ++c.dropped;
    ++counters_.dropped;
    return false;
  }
  ++c.messages;
  c.bytes += static_cast<int64_t>(size);
  ++counters_.sent;
  return true;
}

void Node::on_clock_message(const semx::clock_t& msg) {
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
  if (decision.ack && !skip_ack) {
    semx::ack_t ack;
    ack.utime = msg.utime;
    ack.node = options_.name;
    ack.tick = msg.tick;
    ack.quiet_until = quiet_until_fn_ ? quiet_until_fn_(msg.utime) : 0;
    publish(channels::SIM_ACK, ack);
    quiet_until_ = ack.quiet_until;
    last_ack_utime_ = msg.utime;
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

void Node::set_time(int64_t utime, int64_t tick) { clock_.on_clock(tick, utime, clock_.mode()); }

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
  if (now >= next_status_) publish_status();
  const auto until_status = std::chrono::duration_cast<std::chrono::milliseconds>(next_status_ - now).count();
  const int wait = static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(timeout_ms, until_status)));
  if (udpm_) return receive_once(wait);
  const int rc = lcm_->handleTimeout(wait);
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
  if (!got) return 0;
  // liblcm calls a channel's handlers in the order they subscribed; the typed subscription of a
  // channel comes before any pattern here (SIM_CLOCK is subscribed in the constructor).
  if (subs_.count(*m.channel)) on_message(*m.channel, m.data, m.size);
  if (!raw_handlers_.empty()) on_raw_message(*m.channel, m.data, m.size);
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
