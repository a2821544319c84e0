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

void LcmReassembler::abandon(std::map<Key, Pending>::iterator it) {
  pending_bytes_ -= it->second.data.size();
  pending_.erase(it);
  ++counters_.incomplete;
}

void LcmReassembler::make_room(std::size_t bytes, uint64_t sender) {
  auto oldest_of = [&](bool this_sender) {
    auto best = pending_.end();
    auto it = this_sender ? pending_.lower_bound(Key{sender, 0}) : pending_.begin();
    std::size_t n = 0;
    for (; it != pending_.end() && (!this_sender || it->first.sender == sender); ++it, ++n) {
      if (best == pending_.end() || it->second.started < best->second.started) best = it;
    }
    return std::make_pair(best, n);
  };
  for (;;) {
    const auto [oldest, n] = oldest_of(true);
    if (n < kMaxPendingPerSender) break;
    abandon(oldest);
  }
  while (!pending_.empty() && (pending_bytes_ + bytes > pending_budget_ || pending_.size() >= kMaxPending))
    abandon(oldest_of(false).first);
}

bool LcmReassembler::recently_done(const Key& key, uint32_t size, double now_s) {
  std::size_t expired = 0;
  while (expired < done_recent_.size() && now_s - done_recent_[expired].at > kDoneMemoryS) ++expired;
  done_recent_.erase(done_recent_.begin(), done_recent_.begin() + static_cast<std::ptrdiff_t>(expired));
  for (const Done& d : done_recent_)
    if (d.key == key && d.size == size) return true;
  return false;
}

bool LcmReassembler::next_tail(Tail* out) {
  if (tails_.empty()) return false;
  *out = std::move(tails_.front());
  tails_.pop_front();
  return true;
}

DatagramError LcmReassembler::feed(uint64_t sender, const uint8_t* data, std::size_t size,
                                   LcmMessageView* out, bool* complete, double now_s) {
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
  } else if (be32(data) == kLcmMagicLong || be32(data) == kSemxMagicResend) {
    e = feed_fragment(sender, data, size, out, complete, be32(data) == kSemxMagicResend, now_s);
  } else {
    e = DatagramError::kMagic;
  }
  if (e != DatagramError::kNone) ++counters_.rejected;
  return e;
}

DatagramError LcmReassembler::feed_fragment(uint64_t sender, const uint8_t* data, std::size_t size,
                                            LcmMessageView* out, bool* complete, bool resend, double now_s) {
  if (size < kLcmLongHeader) return DatagramError::kTooShort;
  const uint32_t seqno = be32(data + 4);
  const uint32_t msg_size = be32(data + 8);
  const uint32_t offset = be32(data + 12);
  const uint16_t number = be16(data + 16);
  const uint16_t count = be16(data + 18);
  if (count == 0 || number >= count) return DatagramError::kFragment;
  if (msg_size > max_message_bytes_) return DatagramError::kTooLarge;

  std::size_t at = kLcmLongHeader;
  int name_len = 0;
  if (number == 0) {
    name_len = lcm_channel_length(data + at, size - at);
    if (name_len < 0) return DatagramError::kChannel;
    if (offset != 0) return DatagramError::kFragment;
    at += static_cast<std::size_t>(name_len) + 1;
  }
  const std::size_t n = size - at;
  if (offset > msg_size || n > msg_size - offset) return DatagramError::kFragment;

  const Key key{sender, seqno};
  auto it = pending_.find(key);
  if (it != pending_.end()) {
    const Pending& p = it->second;
    const bool stale = now_s > 0 && now_s - p.created_s > kPendingMaxAgeS;
    const bool other = p.size != msg_size || p.count != count;
    // The sender's counter came round, or a first fragment starts another message under a seqno
    // still held: the old one will not be finished.
    if (stale || (other && number == 0 && !resend)) {
      abandon(it);
      it = pending_.end();
    } else if (other) {
      return DatagramError::kFragment;
    }
  }
  if (it == pending_.end()) {
    if (resend && recently_done(key, msg_size, now_s)) {
      ++counters_.spare;  // the rest of a copy that came after the message was whole
      return DatagramError::kNone;
    }
    if (number != 0 && !resend && !seqno_tagged(seqno)) {
      // The first fragment was filtered out (a channel nobody here reads) or lost.
      ++counters_.orphans;
      return DatagramError::kNone;
    }
    if (number == 0 && !resend) {  // a new message under this seqno: not the one completed before
      done_recent_.erase(std::remove_if(done_recent_.begin(), done_recent_.end(),
                                        [&](const Done& d) { return d.key == key; }),
                         done_recent_.end());
    }
    make_room(msg_size, sender);
    it = pending_.emplace(key, Pending{}).first;
    Pending& p = it->second;
    p.started = ++started_;
    p.created_s = now_s;
    p.size = msg_size;
    p.count = count;
    p.remaining = count;
    p.seen.assign(count, false);
    p.data.resize(msg_size);
    pending_bytes_ += msg_size;
  }
  Pending& p = it->second;
  if (p.seen[number]) {
    if (resend) {
      ++counters_.spare;
      return DatagramError::kNone;
    }
    return DatagramError::kFragment;  // the same original fragment twice
  }
  if (n) std::memcpy(p.data.data() + offset, data + at, n);
  if (number == 0)
    p.channel.assign(reinterpret_cast<const char*>(data + kLcmLongHeader),
                     static_cast<std::size_t>(name_len));
  p.seen[number] = true;
  p.resent = p.resent || resend;
  if (--p.remaining > 0) {
    // The message's last bytes came and it is still incomplete: say so once, so the reader can
    // ask for it before any later message of its channel comes whole (at 10 % loss a 1 MB
    // message seldom does).
    if (tail_bytes_ > 0 && !p.tail_told && number + 1u == count && msg_size - offset >= tail_bytes_ &&
        msg_size >= tail_bytes_ && tails_.size() < kMaxTails) {
      p.tail_told = true;
      tails_.push_back(
          {sender, seqno,
           std::vector<uint8_t>(p.data.end() - static_cast<std::ptrdiff_t>(tail_bytes_), p.data.end())});
    }
    return DatagramError::kNone;
  }
  if (p.resent) ++counters_.filled;
  pending_bytes_ -= p.data.size();
  done_.swap(p.data);
  channel_.swap(p.channel);
  pending_.erase(it);
  if (done_recent_.size() >= 256) done_recent_.erase(done_recent_.begin());
  done_recent_.push_back({key, msg_size, now_s});
  out->channel = &channel_;
  out->data = done_.data();
  out->size = done_.size();
  *complete = true;
  return DatagramError::kNone;
}

}  // namespace semx::runtime
