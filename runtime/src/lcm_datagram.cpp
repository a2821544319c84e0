#include "semx/runtime/lcm_datagram.hpp"

#include <algorithm>
#include <cstring>

namespace semx::runtime {

namespace {

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

}  // namespace

const char* to_string(DatagramError e) {
  switch (e) {
    case DatagramError::kNone:
      return "ok";
    case DatagramError::kTooShort:
      return "shorter than its header";
    case DatagramError::kMagic:
      return "not an LCM datagram (magic)";
    case DatagramError::kChannel:
      return "bad channel name";
    case DatagramError::kFragment:
      return "inconsistent fragment";
    case DatagramError::kTooLarge:
      return "message larger than the limit";
  }
  return "?";
}

int lcm_channel_length(const uint8_t* p, std::size_t left) {
  const std::size_t n = left < kLcmMaxChannel + 1 ? left : kLcmMaxChannel + 1;
  const void* nul = std::memchr(p, 0, n);
  if (!nul) return -1;
  const int len = static_cast<int>(static_cast<const uint8_t*>(nul) - p);
  return len > 0 ? len : -1;
}

LcmReassembler::LcmReassembler(std::size_t max_message_bytes)
    : max_message_bytes_(max_message_bytes),
      pending_budget_(std::max<std::size_t>(2 * max_message_bytes, 64u << 20)) {}

void LcmReassembler::make_room(std::size_t bytes, uint64_t keep, bool adding) {
  while (pending_bytes_ + bytes > pending_budget_ || (adding && pending_.size() >= kMaxPendingSenders)) {
    auto oldest = pending_.end();
    for (auto it = pending_.begin(); it != pending_.end(); ++it) {
      if (it->first != keep && (oldest == pending_.end() || it->second.started < oldest->second.started))
        oldest = it;
    }
    if (oldest == pending_.end()) return;
    pending_bytes_ -= oldest->second.data.size();
    pending_.erase(oldest);
    ++counters_.incomplete;
  }
}

DatagramError LcmReassembler::feed(uint64_t sender, const uint8_t* data, std::size_t size,
                                   LcmMessageView* out, bool* complete) {
  ++counters_.datagrams;
  *complete = false;
  DatagramError e = DatagramError::kNone;
  if (size < 4) {
    e = DatagramError::kTooShort;
  } else if (be32(data) == kLcmMagicShort) {
    if (size < kLcmShortHeader + 1) {
      e = DatagramError::kTooShort;
    } else {
      const int len = lcm_channel_length(data + kLcmShortHeader, size - kLcmShortHeader);
      const std::size_t payload = kLcmShortHeader + static_cast<std::size_t>(len) + 1;
      if (len < 0) {
        e = DatagramError::kChannel;
      } else if (size - payload > max_message_bytes_) {
        e = DatagramError::kTooLarge;
      } else {
        channel_.assign(reinterpret_cast<const char*>(data + kLcmShortHeader), static_cast<std::size_t>(len));
        out->channel = &channel_;
        out->data = data + payload;
        out->size = size - payload;
        *complete = true;
      }
    }
  } else if (be32(data) == kLcmMagicLong) {
    e = feed_fragment(sender, data, size, out, complete);
  } else {
    e = DatagramError::kMagic;
  }
  if (e != DatagramError::kNone) ++counters_.rejected;
  return e;
}

DatagramError LcmReassembler::feed_fragment(uint64_t sender, const uint8_t* data, std::size_t size,
                                            LcmMessageView* out, bool* complete) {
  if (size < kLcmLongHeader) return DatagramError::kTooShort;
  const uint32_t seqno = be32(data + 4);
  const uint32_t msg_size = be32(data + 8);
  const uint32_t offset = be32(data + 12);
  const uint16_t number = be16(data + 16);
  const uint16_t count = be16(data + 18);
  if (count == 0 || number >= count) return DatagramError::kFragment;
  if (msg_size > max_message_bytes_) return DatagramError::kTooLarge;

  std::size_t at = kLcmLongHeader;
  auto it = pending_.find(sender);
  if (number == 0) {
    const int len = lcm_channel_length(data + at, size - at);
    if (len < 0) return DatagramError::kChannel;
    if (offset != 0) return DatagramError::kFragment;
    at += static_cast<std::size_t>(len) + 1;
    if (size - at > msg_size) return DatagramError::kFragment;
    if (it != pending_.end()) {
      ++counters_.incomplete;  // the sender moved on: what is missing will not come
      pending_bytes_ -= it->second.data.size();
      it->second.data.clear();
    }
    make_room(msg_size, sender, it == pending_.end());
    if (it == pending_.end()) it = pending_.emplace(sender, Pending{}).first;
    Pending& p = it->second;
    p.started = ++started_;
    p.seqno = seqno;
    p.size = msg_size;
    p.remaining = count;
    p.seen.assign(count, false);
    p.channel.assign(reinterpret_cast<const char*>(data + kLcmLongHeader), static_cast<std::size_t>(len));
    p.data.resize(msg_size);
    pending_bytes_ += msg_size;
  } else if (it == pending_.end() || it->second.seqno != seqno) {
    // The first fragment was filtered out (a channel nobody here reads) or lost.
    ++counters_.orphans;
    return DatagramError::kNone;
  }
  Pending& p = it->second;
  const std::size_t n = size - at;
  if (p.seen.size() != count || p.seen[number] || offset > p.size || n > p.size - offset) {
    return DatagramError::kFragment;
  }
  if (n) std::memcpy(p.data.data() + offset, data + at, n);
  p.seen[number] = true;
  if (--p.remaining > 0) return DatagramError::kNone;
  pending_bytes_ -= p.data.size();
  done_.swap(p.data);
  channel_.swap(p.channel);
  pending_.erase(it);
  out->channel = &channel_;
  out->data = done_.data();
  out->size = done_.size();
  *complete = true;
  return DatagramError::kNone;
}

}  // namespace semx::runtime
