#include "semx/runtime/udpm_sender.hpp"

#include "semx/runtime/executable_dir.hpp"
#include "semx/runtime/monotonic_clock.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace semx::runtime {

namespace {

void put32(uint8_t* p, uint32_t v) {
  p[0] = static_cast<uint8_t>(v >> 24);
  p[1] = static_cast<uint8_t>(v >> 16);
  p[2] = static_cast<uint8_t>(v >> 8);
  p[3] = static_cast<uint8_t>(v);
}
void put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}

}  // namespace

uint32_t channel_tag(const std::string& channel) {
  uint32_t h = 2166136261u;  // FNV-1a
  for (char c : channel) h = (h ^ static_cast<uint8_t>(c)) * 16777619u;
  return 1 + (h ^ (h >> 20)) % kSeqnoTagBits;
}

UdpmSender::UdpmSender(const UdpmEndpoint& endpoint, BusPace pace, double foreign_hold_s)
    : pacer_(pace), header_(kLcmLongHeader + kLcmMaxChannel + 1) {
  if (foreign_hold_s > 0) {
    listeners_ = std::make_unique<BusListeners>(endpoint.port, executable_dir(), foreign_hold_s);
    foreign_room_ = foreign_room_bytes();
  }
  const std::string name = "udpm://" + endpoint.group + ":" + std::to_string(endpoint.port);
  auto fail = [&](const char* what) {
    const std::string msg = name + ": " + what + ": " + std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(msg);
  };
  in_addr group{};
  if (inet_aton(endpoint.group.c_str(), &group) == 0) {
    errno = EINVAL;
    fail("group address");
  }
  group_ = group.s_addr;
  port_ = htons(static_cast<uint16_t>(endpoint.port));
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail("socket");
  const unsigned char ttl = static_cast<unsigned char>(endpoint.ttl);
  if (setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0) fail("IP_MULTICAST_TTL");
  const unsigned char loop = 1;  // the processes on this host are the readers
  if (setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0) fail("IP_MULTICAST_LOOP");
}

UdpmSender::~UdpmSender() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpmSender::publish(const std::string& channel, const uint8_t* data, std::size_t size,
                         uint32_t* seqno_out) {
  if (channel.empty() || channel.size() > kLcmMaxChannel || channel.find('\0') != std::string::npos)
    return false;
  const uint32_t seqno = kSeqnoTagged | (channel_tag(channel) << kSeqnoTagShift) | counter_++;
  if (seqno_out) *seqno_out = seqno;
  return send_message(channel, data, size, seqno, kLcmMagicLong);
}

bool UdpmSender::publish_again(const std::string& channel, const uint8_t* data, std::size_t size,
                               uint32_t seqno) {
  if (channel.empty() || channel.size() > kLcmMaxChannel || channel.find('\0') != std::string::npos)
    return false;
  if (kLcmShortHeader + channel.size() + 1 + size <= kMaxDatagram) return publish(channel, data, size);
  return send_message(channel, data, size, seqno, kSemxMagicResend);
}

bool UdpmSender::send_message(const std::string& channel, const uint8_t* data, std::size_t size,
                              uint32_t seqno, uint32_t fragment_magic) {
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = group_;
  to.sin_port = port_;
  iovec iov[2];
  msghdr msg{};
  msg.msg_name = &to;
  msg.msg_namelen = sizeof to;
  msg.msg_iov = iov;
  msg.msg_iovlen = 2;
  auto send = [&](std::size_t header, const uint8_t* part, std::size_t n) {
    // Every datagram, not only a large one, goes once a reader outside the set has room: a
    // 64 KB fragment taken into a queue that was not yet full can leave it full, and a small
    // message sent next without a look (another node's status) was what the kernel dropped.
    if (listeners_) {
      while (!listeners_->has_room(monotonic_s(), foreign_room_))
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (pacer_.active()) {
      const double wait_s = pacer_.delay(header + n, monotonic_s());
      if (wait_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    }
    iov[0] = {header_.data(), header};
    iov[1] = {const_cast<uint8_t*>(part), n};
    return ::sendmsg(fd_, &msg, 0) == static_cast<ssize_t>(header + n);
  };
  const std::size_t name = channel.size() + 1;
  if (kLcmShortHeader + name + size <= kMaxDatagram) {
    put32(header_.data(), kLcmMagicShort);
    put32(header_.data() + 4, seqno);
    std::memcpy(header_.data() + kLcmShortHeader, channel.c_str(), name);
    return send(kLcmShortHeader + name, data, size);
  }
  if (size > 0xffffffffu) return false;
  // Fragment 0 carries the name, so it holds that much less data.
  const std::size_t room = kMaxDatagram - kLcmLongHeader;
  const std::size_t first = room - name;
  const std::size_t count = 1 + (size - first + room - 1) / room;
  if (count > 0xffff) return false;
  put32(header_.data(), fragment_magic);
  put32(header_.data() + 4, seqno);
  put32(header_.data() + 8, static_cast<uint32_t>(size));
  put16(header_.data() + 18, static_cast<uint16_t>(count));
  std::size_t offset = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t n = std::min(k == 0 ? first : room, size - offset);
    put32(header_.data() + 12, static_cast<uint32_t>(offset));
    put16(header_.data() + 16, static_cast<uint16_t>(k));
    std::size_t header = kLcmLongHeader;
    if (k == 0) {
      std::memcpy(header_.data() + kLcmLongHeader, channel.c_str(), name);
      header += name;
    }
    if (!send(header, data + offset, n)) return false;
    offset += n;
  }
  return true;
}

}  // namespace semx::runtime
