#include "semx/runtime/udpm_receiver.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/udpm_sender.hpp"

namespace semx::runtime {

namespace {

constexpr const char* kDefaultGroup = "239.255.76.67";
constexpr int kDefaultPort = 7667;
// The largest UDP payload; liblcm's fragments stay below it.
constexpr std::size_t kMaxDatagram = 65536;
// Beyond this many channels the program passes everything (the caller still filters).
constexpr std::size_t kMaxFilterChannels = 200;

bool parse_int(const std::string& s, long max, long* out) {
  if (s.empty() || s.size() > 10) return false;
  long v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  if (v > max) return false;
  *out = v;
  return true;
}

// Compares the channel name at X + 0 (X: where the name starts) with `name` and its NUL, four,
// two or one byte at a time; the whole block falls through to its RET on a match and jumps past
// it on the first difference.
void append_channel_block(const std::string& name, uint32_t on_match, std::vector<sock_filter>& prog) {
  std::string bytes = name;
  bytes.push_back('\0');
  std::vector<sock_filter> block;
  std::size_t i = 0;
  while (i < bytes.size()) {
    const std::size_t left = bytes.size() - i;
    const std::size_t w = left >= 4 ? 4 : left >= 2 ? 2 : 1;
    uint32_t v = 0;
    for (std::size_t k = 0; k < w; ++k) v = (v << 8) | static_cast<uint8_t>(bytes[i + k]);
    const uint16_t size = w == 4 ? BPF_W : w == 2 ? BPF_H : BPF_B;
    block.push_back(BPF_STMT(BPF_LD | size | BPF_IND, static_cast<uint32_t>(i)));
    block.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, v, 0, 0));  // jf set below
    i += w;
  }
  block.push_back(BPF_STMT(BPF_RET | BPF_K, on_match));
  for (std::size_t k = 0; k < block.size(); ++k) {
    if (BPF_CLASS(block[k].code) == BPF_JMP) block[k].jf = static_cast<uint8_t>(block.size() - k - 1);
  }
  prog.insert(prog.end(), block.begin(), block.end());
}

// What the kernel holds for the socket: SO_RCVBUF reads back twice the payload it grants
// (socket(7)), so half of it is comparable with what was asked.
int read_recv_buf(int fd) {
  int got = 0;
  socklen_t len = sizeof got;
  if (getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &got, &len) != 0) return 0;
  return got / 2;
}

}  // namespace

std::optional<UdpmEndpoint> parse_udpm_url(const std::string& url) {
  const std::string scheme = "udpm://";
  if (url.compare(0, scheme.size(), scheme) != 0) return std::nullopt;
  const std::size_t q = url.find('?', scheme.size());
  const std::string network =
      url.substr(scheme.size(), q == std::string::npos ? std::string::npos : q - scheme.size());
  UdpmEndpoint e;
  e.group = kDefaultGroup;
  e.port = kDefaultPort;
  const std::size_t colon = network.find(':');
  const std::string address = network.substr(0, colon);
  if (!address.empty()) e.group = address;
  in_addr a{};
  if (inet_aton(e.group.c_str(), &a) == 0 || !IN_MULTICAST(ntohl(a.s_addr))) return std::nullopt;
  if (colon != std::string::npos) {
    long port = 0;
    if (!parse_int(network.substr(colon + 1), 65535, &port) || port == 0) return std::nullopt;
    e.port = static_cast<int>(port);
  }
  std::size_t at = q == std::string::npos ? url.size() : q + 1;
  while (at < url.size()) {
    const std::size_t amp = url.find('&', at);
    const std::string option = url.substr(at, amp == std::string::npos ? std::string::npos : amp - at);
    at = amp == std::string::npos ? url.size() : amp + 1;
    const std::size_t eq = option.find('=');
    if (eq == std::string::npos) return std::nullopt;
    const std::string key = option.substr(0, eq);
    long value = 0;
    if (!parse_int(option.substr(eq + 1), 1L << 30, &value)) return std::nullopt;
    if (key == "recv_buf_size") {
      e.recv_buf_size = static_cast<int>(value);
    } else if (key == "ttl" && value <= 255) {
      e.ttl = static_cast<int>(value);
    } else {
      return std::nullopt;
    }
  }
  return e;
}

std::vector<sock_filter> lcm_channel_filter(const std::vector<std::string>& channels, bool refuse) {
  const uint32_t payload = 8;  // after the UDP header
  const uint32_t accept = 0xffffffffu;
  const uint32_t listed = refuse ? 0 : accept, unlisted = refuse ? accept : 0;
  std::vector<sock_filter> names;  // one block per channel, X = where the name starts
  std::vector<uint32_t> tags;
  if (channels.size() > kMaxFilterChannels) return {BPF_STMT(BPF_RET | BPF_K, accept)};  // jumps are 8-bit
  for (const auto& c : channels) {
    if (c.empty() || c.size() > kLcmMaxChannel) continue;  // no datagram can carry it
    append_channel_block(c, listed, names);
    tags.push_back(channel_tag(c));
  }
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());

  std::vector<sock_filter> prog;
  const uint32_t names_at = 14;
  const uint32_t tags_at = names_at + static_cast<uint32_t>(names.size()) + 1;
  prog.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, payload));  // 0: magic
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kLcmMagicShort, 0, 2));
  prog.push_back(BPF_STMT(BPF_LDX | BPF_W | BPF_IMM, payload + static_cast<uint32_t>(kLcmShortHeader)));
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JA, names_at - 4, 0, 0));
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kLcmMagicLong, 0, 4));  // 4: else to 9
  prog.push_back(BPF_STMT(BPF_LD | BPF_H | BPF_ABS, payload + 16));          // fragment number
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, 0, 6, 0));              // the first: to 13
  prog.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, payload + 4));           // 7: a later one's seqno
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JA, tags_at - 9, 0, 0));
  // 9: a fragment sent again (every one of them, the first too) is judged by its tag.
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kSemxMagicResend, 0, 2));
  prog.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, payload + 4));
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JA, tags_at - 12, 0, 0));
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, 0));  // 12: not LCM's
  prog.push_back(BPF_STMT(BPF_LDX | BPF_W | BPF_IMM, payload + static_cast<uint32_t>(kLcmLongHeader)));
  prog.insert(prog.end(), names.begin(), names.end());  // 14: each block returns on a match
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, unlisted));
  // tags_at: A = seqno. Untagged (another sender) passes; a tag is judged like a name.
  prog.push_back(BPF_STMT(BPF_ST, 0));
  prog.push_back(BPF_STMT(BPF_ALU | BPF_AND | BPF_K, kSeqnoTagMask));
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kSeqnoTagged, 1, 0));
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, accept));
  prog.push_back(BPF_STMT(BPF_LD | BPF_MEM, 0));
  prog.push_back(BPF_STMT(BPF_ALU | BPF_RSH | BPF_K, kSeqnoTagShift));
  prog.push_back(BPF_STMT(BPF_ALU | BPF_AND | BPF_K, kSeqnoTagBits));
  for (std::size_t i = 0; i < tags.size(); ++i) {
    // A match jumps over the remaining tests and the unlisted return to the listed one.
    prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, tags[i], static_cast<uint8_t>(tags.size() - i), 0));
  }
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, unlisted));
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, listed));
  return prog;
}

UdpmReceiver::UdpmReceiver(const UdpmEndpoint& endpoint, std::size_t max_message_bytes)
    : buffer_(kMaxDatagram), reassembler_(max_message_bytes) {
  name_ = "udpm://" + endpoint.group + ":" + std::to_string(endpoint.port);
  auto fail = [&](const char* what) {
    const std::string msg = name_ + ": " + what + ": " + std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(msg);
  };
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail("socket");
  // Before bind and join, so no datagram is queued unfiltered.
  filter({}, false);
  const int one = 1;
  if (setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) fail("SO_REUSEADDR");
  {
    // The kernel silently caps SO_RCVBUF at net.core.rmem_max (208 KiB on a stock kernel, where
    // an env3 mapper integrated 406 of 1149 depth frames): ask, read back what was granted, and
    // force it where allowed (root). Node refuses to start with less than it asked for.
    const int size = endpoint.recv_buf_size > 0 ? endpoint.recv_buf_size : kDefaultRecvBufBytes;
    if (setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &size, sizeof size) != 0) fail("SO_RCVBUF");
    requested_recv_buf_ = size;
    granted_recv_buf_ = read_recv_buf(fd_);
    if (granted_recv_buf_ < size) {
      setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &size, sizeof size);  // CAP_NET_ADMIN only
      granted_recv_buf_ = read_recv_buf(fd_);
    }
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(endpoint.port));
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  if (bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) fail("bind");
  ip_mreq mreq{};
  if (inet_aton(endpoint.group.c_str(), &mreq.imr_multiaddr) == 0) {
    errno = EINVAL;
    fail("group address");
  }
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) fail("IP_ADD_MEMBERSHIP");
}

UdpmReceiver::~UdpmReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpmReceiver::filter(const std::vector<std::string>& channels, bool all,
                          const std::vector<std::string>& refused) {
  std::vector<sock_filter> prog = all ? lcm_channel_filter(refused, true) : lcm_channel_filter(channels);
  sock_fprog fprog{};
  fprog.len = static_cast<unsigned short>(prog.size());
  fprog.filter = prog.data();
  if (setsockopt(fd_, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0) {
    throw std::runtime_error(name_ + ": SO_ATTACH_FILTER (" + std::to_string(prog.size()) +
                             " instructions): " + std::strerror(errno));
  }
}

namespace {
uint64_t xorshift(uint64_t& state) {  // a test's own, repeatable draws
  state ^= state << 13;
  state ^= state >> 7;
  state ^= state << 17;
  return state;
}
}  // namespace

bool UdpmReceiver::drop_now() {
  if (drop_rate_ <= 0) return false;
  if (static_cast<double>(xorshift(drop_state_) >> 11) * 0x1.0p-53 >= drop_rate_) return false;
  ++dropped_for_test_;
  return true;
}

bool UdpmReceiver::read_datagram(std::size_t* n, uint64_t* sender) {
  for (;;) {
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t got = ::recvfrom(fd_, buffer_.data(), buffer_.size(), MSG_DONTWAIT | MSG_TRUNC,
                                   reinterpret_cast<sockaddr*>(&from), &from_len);
    if (got < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) ++socket_errors_;
      return false;
    }
    if (drop_now()) continue;
    if (static_cast<std::size_t>(got) > buffer_.size()) {  // MSG_TRUNC: longer than any UDP payload
      last_error_ = DatagramError::kTooLarge;
      continue;
    }
    *n = static_cast<std::size_t>(got);
    *sender = (uint64_t{ntohl(from.sin_addr.s_addr)} << 16) | ntohs(from.sin_port);
    return true;
  }
}

bool UdpmReceiver::next(LcmMessageView* out) {
  if (delay_max_s_ > 0) return next_delayed(out);
  std::size_t n = 0;
  uint64_t sender = 0;
  while (read_datagram(&n, &sender)) {
    bool complete = false;
    const DatagramError e = reassembler_.feed(sender, buffer_.data(), n, out, &complete, monotonic_s());
    if (e != DatagramError::kNone) last_error_ = e;
    if (complete) return true;
  }
  return false;
}

bool UdpmReceiver::next_delayed(LcmMessageView* out) {
  const double now = monotonic_s();
  std::size_t n = 0;
  uint64_t sender = 0;
  while (read_datagram(&n, &sender)) {
    const double u = static_cast<double>(xorshift(delay_state_) >> 11) * 0x1.0p-53;
    delayed_.push({now + u * delay_max_s_, delay_order_++, sender,
                   std::vector<uint8_t>(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n))});
  }
  while (!delayed_.empty() && delayed_.top().due <= now) {
    // priority_queue's top is const: the bytes are moved out through a cast, then popped.
    current_ = std::move(const_cast<Delayed&>(delayed_.top()).bytes);
    const uint64_t from = delayed_.top().sender;
    delayed_.pop();
    bool complete = false;
    const DatagramError e = reassembler_.feed(from, current_.data(), current_.size(), out, &complete, now);
    if (e != DatagramError::kNone) last_error_ = e;
    if (complete) return true;
  }
  return false;
}

bool UdpmReceiver::wait(int timeout_ms) const {
  if (!delayed_.empty()) {
    const double until_due = delayed_.top().due - monotonic_s();
    if (until_due <= 0) return true;
    timeout_ms = std::min(timeout_ms, static_cast<int>(std::ceil(until_due * 1000)));
    pollfd p{fd_, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) > 0 || delayed_.top().due <= monotonic_s();
  }
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0;
}

}  // namespace semx::runtime
