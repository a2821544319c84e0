#include "semx/runtime/delivery.hpp"

#include <algorithm>

namespace semx::runtime {

void Inbox::reads(uint32_t tag) {
  if (tags_.insert(tag).second && ticked_) fresh_tags_.insert(tag);
}

Inbox::Arrival Inbox::arrive(const StreamKey& s, uint32_t seq, const std::string& channel,
                             const uint8_t* bytes, std::size_t size, double now) {
  if (s.sender == self_) return Arrival::kDeliver;  // its own messages, looped back
  Stream& st = streams_[s];
  if (st.next == 0) {
    // A late reader not yet started (no tick seen, or the channel just subscribed) starts with
    // what it gets; otherwise nothing of a publisher before seq 1 was missed.
    st.next = !o_.from_start && (!ticked_ || fresh_tags_.count(s.tag)) ? seq : 1;
  }
  if (seq < st.next || st.held.count(seq)) {
    ++counters_.duplicates;
    return Arrival::kDuplicate;
  }
  if (seq > st.next) {
    Held& h = st.held[seq];
    h.channel = channel;
    h.bytes.assign(bytes, bytes + size);
    held_bytes_ += size;
    st.want = std::max(st.want, seq);
    if (st.gap_since < 0) st.gap_since = now;
    return Arrival::kHeld;
  }
  if (st.last_request >= 0) ++counters_.recovered;
  ++st.next;
  release(s, st);
  return Arrival::kDeliver;
}

void Inbox::release(const StreamKey& key, Stream& st) {
  for (auto it = st.held.begin(); it != st.held.end() && it->first == st.next; it = st.held.erase(it)) {
    held_bytes_ -= it->second.bytes.size();
    ready_.push_back({std::move(it->second.channel), std::move(it->second.bytes), key, it->first});
    ++st.next;
  }
  if (!missing(st)) st.gap_since = -1;
  if (!asking(st)) st.last_request = -1;
}

bool Inbox::tick(const std::vector<StreamHead>& heads, double now) {
  for (const StreamHead& h : heads) {
    if (h.stream.sender == self_ || !tags_.count(h.stream.tag) || h.seq == 0) continue;
    Stream& st = streams_[h.stream];
    if (st.next == 0) {
      const bool fresh = fresh_tags_.count(h.stream.tag) || (!ticked_ && !o_.from_start);
      st.next = fresh ? h.seq + 1 : 1;
    }
    if (h.seq >= st.next) {
      st.want = std::max(st.want, h.seq);
      if (st.gap_since < 0) st.gap_since = now;
    }
  }
  ticked_ = true;
  fresh_tags_.clear();
  return complete();
}

void Inbox::hint(const StreamKey& s, uint32_t seq) {
  if (s.sender == self_ || !tags_.count(s.tag) || seq == 0) return;
  auto it = streams_.find(s);
  if (it == streams_.end()) {
    // Not from a stranger's lie a new stream: the caller names only senders it verified.
    if (!o_.from_start || seq > kMaxHintAhead) return;
    it = streams_.emplace(s, Stream{}).first;
    it->second.next = 1;
  }
  Stream& st = it->second;
  if (st.next == 0 || seq < st.next || seq > std::max(st.want, st.next) + kMaxHintAhead) return;
  st.hinted = std::max(st.hinted, seq);
}

bool Inbox::complete() const {
  for (const auto& [key, st] : streams_) {
    if (missing(st)) return false;
  }
  return true;
}

std::vector<ResendRequest> Inbox::requests(double now) {
  std::vector<ResendRequest> out;
  for (auto& [key, st] : streams_) {
    if (!asking(st)) continue;
    const uint32_t want = std::max(st.want, st.hinted);
    // Runs not asked for yet go out at once; runs asked for already, again every retry_s (the
    // answer may be on its way). Every run of the stream, or a busy stream falls further behind
    // than its publisher keeps.
    const bool retry = st.last_request < 0 || now - st.last_request >= o_.retry_s;
    bool any = false;
    uint32_t seq = st.next;
    auto held = st.held.begin();
    for (int runs = 0; seq <= want && runs < 32; ++runs) {
      while (held != st.held.end() && held->first < seq) ++held;
      while (held != st.held.end() && held->first == seq) {
        ++seq;
        ++held;
      }
      if (seq > want) break;
      const uint32_t last = held == st.held.end() ? want : std::min(want, held->first - 1);
      if (retry || last > st.asked) {
        out.push_back({key, retry ? seq : std::max(seq, st.asked + 1), last});
        ++counters_.requests;
        any = true;
      }
      seq = last + 1;
    }
    if (any && retry) st.last_request = now;
    st.asked = std::max(st.asked, want);
  }
  return out;
}

std::vector<ResendRequest> Inbox::give_up(double now) {
  std::vector<ResendRequest> lost;
  for (auto& [key, st] : streams_) {
    if (!missing(st)) continue;
    const bool too_long = st.gap_since >= 0 && now - st.gap_since >= o_.give_up_s;
    if (!too_long && held_bytes_ <= o_.max_held_bytes) continue;
    while (st.next <= st.want) {
      if (st.held.count(st.next)) {
        release(key, st);
        continue;
      }
      if (lost.empty() || lost.back().stream.sender != key.sender || lost.back().stream.tag != key.tag ||
          lost.back().last + 1 != st.next) {
        lost.push_back({key, st.next, st.next});
      } else {
        lost.back().last = st.next;
      }
      ++counters_.lost;
      ++st.next;
    }
    release(key, st);
  }
  return lost;
}

Inbox::Resent Inbox::resent(const StreamKey& s, uint32_t seq) {
  const auto it = streams_.find(s);
  if (it == streams_.end() || it->second.next == 0) return Resent::kUnknown;
  if (seq < it->second.next || it->second.held.count(seq)) {
    ++counters_.duplicates;
    return Resent::kDuplicate;
  }
  return Resent::kAwaited;
}

bool Inbox::ready(Ready* out) {
  if (ready_.empty()) return false;
  *out = std::move(ready_.front());
  ready_.pop_front();
  return true;
}

std::vector<uint8_t> ResendHistory::keep(const std::string& channel, uint32_t tag, uint32_t seq,
                                         std::vector<uint8_t>&& bytes, uint32_t wire_seqno) {
  Channel& c = channels_[tag];
  if (c.name.empty()) c.name = channel;
  c.bytes += bytes.size();
  total_bytes_ += bytes.size();
  c.kept.push_back({seq, std::move(bytes), wire_seqno});
  std::vector<uint8_t> reuse;
  while (c.kept.size() > 1 && (c.kept.size() > per_channel_ || c.bytes > bytes_per_channel_)) {
    c.bytes -= c.kept.front().bytes.size();
    total_bytes_ -= c.kept.front().bytes.size();
    reuse = std::move(c.kept.front().bytes);
    c.kept.pop_front();
  }
  reuse.clear();
  return reuse;
}

const std::vector<uint8_t>* ResendHistory::find(uint32_t tag, uint32_t seq, const std::string** channel,
                                                uint32_t* wire_seqno) const {
  const auto it = channels_.find(tag);
  if (it == channels_.end() || it->second.kept.empty()) return nullptr;
  const auto& kept = it->second.kept;
  // Sequence numbers are consecutive in the deque (every message of the channel is kept).
  const uint32_t first = kept.front().seq;
  if (seq < first || seq - first >= kept.size() || kept[seq - first].seq != seq) return nullptr;
  if (channel) *channel = &it->second.name;
  if (wire_seqno) *wire_seqno = kept[seq - first].wire_seqno;
  return &kept[seq - first].bytes;
}

}  // namespace semx::runtime
