// LcmReassembler: liblcm's udpm datagrams back into messages, and every malformed datagram
// counted and refused without touching memory it does not own.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "semx/runtime/lcm_datagram.hpp"

using namespace semx::runtime;

namespace {

void put32(std::vector<uint8_t>& d, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) d.push_back(static_cast<uint8_t>(v >> s));
}
void put16(std::vector<uint8_t>& d, uint16_t v) {
  d.push_back(static_cast<uint8_t>(v >> 8));
  d.push_back(static_cast<uint8_t>(v));
}

std::vector<uint8_t> small(const std::string& channel, const std::vector<uint8_t>& payload,
                           uint32_t seq = 1) {
  std::vector<uint8_t> d;
  put32(d, kLcmMagicShort);
  put32(d, seq);
  d.insert(d.end(), channel.begin(), channel.end());
  d.push_back(0);
  d.insert(d.end(), payload.begin(), payload.end());
  return d;
}

std::vector<uint8_t> fragment(uint32_t seq, uint32_t size, uint32_t offset, uint16_t number, uint16_t count,
                              const std::string& channel, const std::vector<uint8_t>& part) {
  std::vector<uint8_t> d;
  put32(d, kLcmMagicLong);
  put32(d, seq);
  put32(d, size);
  put32(d, offset);
  put16(d, number);
  put16(d, count);
  if (number == 0) {
    d.insert(d.end(), channel.begin(), channel.end());
    d.push_back(0);
  }
  d.insert(d.end(), part.begin(), part.end());
  return d;
}

std::vector<uint8_t> bytes(std::size_t n, uint8_t seed) {
  std::vector<uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>(seed + 7 * i);
  return v;
}

struct Feed {
  LcmReassembler r{1 << 20};
  LcmMessageView m;
  bool complete = false;
  DatagramError operator()(uint64_t sender, const std::vector<uint8_t>& d, double now_s = 0) {
    return r.feed(sender, d.data(), d.size(), &m, &complete, now_s);
  }
  std::vector<uint8_t> payload() const { return std::vector<uint8_t>(m.data, m.data + m.size); }
};

}  // namespace

TEST(LcmDatagram, SmallMessageGivesChannelAndPayload) {
  Feed f;
  const auto p = bytes(100, 3);
  EXPECT_EQ(f(1, small("ODOMETRY", p)), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "ODOMETRY");
  EXPECT_EQ(f.payload(), p);
  EXPECT_EQ(f(1, small("X", {})), DatagramError::kNone);  // an empty payload is a message
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(f.m.size, 0u);
}

TEST(LcmDatagram, FragmentsAreJoinedInAnyOrderAfterTheFirst) {
  Feed f;
  const auto p = bytes(2500, 9);
  const auto a = std::vector<uint8_t>(p.begin(), p.begin() + 1000);
  const auto b = std::vector<uint8_t>(p.begin() + 1000, p.begin() + 2000);
  const auto c = std::vector<uint8_t>(p.begin() + 2000, p.end());
  EXPECT_EQ(f(5, fragment(42, 2500, 0, 0, 3, "CAMERA_DEPTH", a)), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f(5, fragment(42, 2500, 2000, 2, 3, "", c)), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  // Another sender's message in between does not disturb this one.
  EXPECT_EQ(f(6, small("ODOMETRY", {1, 2})), DatagramError::kNone);
  EXPECT_TRUE(f.complete);
  EXPECT_EQ(f(5, fragment(42, 2500, 1000, 1, 3, "", b)), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "CAMERA_DEPTH");
  EXPECT_EQ(f.payload(), p);
  EXPECT_EQ(f.r.counters().rejected, 0);
  EXPECT_EQ(f.r.counters().incomplete, 0);
}

TEST(LcmDatagram, UntaggedFragmentsWithoutTheirFirstAreOrphansAndInterleavedMessagesBothComplete) {
  Feed f;
  const auto part = bytes(10, 1);
  // liblcm's senders (untagged seqnos): a later fragment before its first is an orphan.
  EXPECT_EQ(f(5, fragment(7, 20, 10, 1, 2, "", part)), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f.r.counters().orphans, 1);
  // A sender's next message does not abandon the one before: on a bus with jitter they come
  // interleaved.
  EXPECT_EQ(f(5, fragment(8, 20, 0, 0, 2, "A", part)), DatagramError::kNone);
  EXPECT_EQ(f(5, fragment(9, 20, 0, 0, 2, "B", part)), DatagramError::kNone);
  EXPECT_EQ(f(5, fragment(8, 20, 10, 1, 2, "", part)), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "A");
  EXPECT_EQ(f(5, fragment(9, 20, 10, 1, 2, "", part)), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "B");
  EXPECT_EQ(f.r.counters().incomplete, 0);
}

TEST(LcmDatagram, ATaggedMessageMayStartWithAnyFragment) {
  // Tagged seqnos (semx's senders) passed the kernel filter for a wanted channel: the first
  // fragment may come last.
  Feed f;
  const auto p = bytes(30, 5);
  const uint32_t seq = kSeqnoTagged | (77u << kSeqnoTagShift) | 3;
  EXPECT_EQ(f(5, fragment(seq, 30, 20, 2, 3, "", {p.begin() + 20, p.end()})), DatagramError::kNone);
  EXPECT_EQ(f(5, fragment(seq, 30, 10, 1, 3, "", {p.begin() + 10, p.begin() + 20})), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f(5, fragment(seq, 30, 0, 0, 3, "DEPTH", {p.begin(), p.begin() + 10})), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "DEPTH");
  EXPECT_EQ(f.payload(), p);
  EXPECT_EQ(f.r.counters().orphans, 0);
}

namespace {
std::vector<uint8_t> resent(std::vector<uint8_t> d) {
  d[0] = 'S', d[1] = 'X', d[2] = 'R', d[3] = '3';
  return d;
}
}  // namespace

TEST(LcmDatagram, AResendFillsTheHolesOfTheFirstCopy) {
  // Fragment 1 of the first copy and fragment 0 of the resend are lost: together they make the
  // message. The rest of the resend, after the message was whole, starts nothing.
  Feed f;
  const auto p = bytes(3000, 11);
  const uint32_t seq = kSeqnoTagged | (5u << kSeqnoTagShift) | 200;
  std::vector<std::vector<uint8_t>> frags;
  for (uint16_t k = 0; k < 3; ++k)
    frags.push_back(fragment(seq, 3000, k * 1000u, k, 3, "ESDF_LOCAL",
                             {p.begin() + k * 1000, p.begin() + (k + 1) * 1000}));
  EXPECT_EQ(f(9, frags[0], 1.0), DatagramError::kNone);
  EXPECT_EQ(f(9, frags[2], 1.0), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f(9, resent(frags[2]), 1.05), DatagramError::kNone);  // held already: spare
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f(9, resent(frags[1]), 1.05), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(*f.m.channel, "ESDF_LOCAL");
  EXPECT_EQ(f.payload(), p);
  EXPECT_EQ(f.r.counters().filled, 1);
  EXPECT_EQ(f(9, resent(frags[0]), 1.06), DatagramError::kNone);  // a second resend's rest
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f.r.counters().spare, 2);
  EXPECT_EQ(f.r.pending_bytes(), 0u);
  EXPECT_EQ(f.r.counters().rejected, 0);
  // A resend of a message whose first copy never came makes it on its own.
  const uint32_t seq2 = seq + 1;
  for (uint16_t k = 0; k < 3; ++k) {
    EXPECT_EQ(f(9,
                resent(fragment(seq2, 3000, k * 1000u, k, 3, "ESDF_LOCAL",
                                {p.begin() + k * 1000, p.begin() + (k + 1) * 1000})),
                1.1),
              DatagramError::kNone);
  }
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(f.payload(), p);
  // A first copy's fragment twice is malformed, as before (a resend's is not).
  EXPECT_EQ(f(9, frags[0], 2.0), DatagramError::kNone);
  EXPECT_EQ(f(9, frags[0], 2.0), DatagramError::kFragment);
}

TEST(LcmDatagram, AStaleIncompleteMessageIsAbandonedWhenItsSeqnoComesRound) {
  // The sender's 8-bit counter came round: a second's old hole is not filled by a new message.
  Feed f;
  const auto a = bytes(20, 1), b = bytes(20, 2);
  const uint32_t seq = kSeqnoTagged | (9u << kSeqnoTagShift) | 1;
  EXPECT_EQ(f(4, fragment(seq, 20, 0, 0, 2, "X", {a.begin(), a.begin() + 10}), 10.0), DatagramError::kNone);
  EXPECT_EQ(f(4, fragment(seq, 20, 10, 1, 2, "", {b.begin() + 10, b.end()}), 12.0), DatagramError::kNone);
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f.r.counters().incomplete, 1);
  EXPECT_EQ(f(4, fragment(seq, 20, 0, 0, 2, "X", {b.begin(), b.begin() + 10}), 12.0), DatagramError::kNone);
  ASSERT_TRUE(f.complete);
  EXPECT_EQ(f.payload(), b);
}

TEST(LcmDatagram, EachSenderHoldsABoundedNumberOfIncompleteMessages) {
  Feed f;
  const auto part = bytes(10, 1);
  const uint32_t n = LcmReassembler::kMaxPendingPerSender + 24;
  for (uint32_t k = 0; k < n; ++k)
    EXPECT_EQ(f(5, fragment(kSeqnoTagged | k, 20, 0, 0, 2, "A", part)), DatagramError::kNone);
  EXPECT_EQ(f.r.counters().incomplete, 24);
  EXPECT_EQ(f(5, fragment(kSeqnoTagged | (n - 1), 20, 10, 1, 2, "", part)), DatagramError::kNone);
  EXPECT_TRUE(f.complete);  // the newest still completes
}

TEST(LcmDatagram, MalformedDatagramsAreRefusedAndCounted) {
  Feed f;
  const auto part = bytes(10, 1);
  std::vector<uint8_t> no_nul = small("ODOMETRY", {});
  no_nul.pop_back();  // the name's NUL
  std::vector<uint8_t> long_name = small(std::string(kLcmMaxChannel + 1, 'A'), part);
  std::vector<uint8_t> bad_magic = small("A", part);
  std::vector<uint8_t> truncated = fragment(1, 20, 0, 0, 2, "A", part);
  truncated.resize(kLcmLongHeader - 1);
  bad_magic[0] = 'X';
  const struct {
    std::vector<uint8_t> d;
    DatagramError e;
  } cases[] = {
      {{}, DatagramError::kTooShort},
      {{0x4c, 0x43}, DatagramError::kTooShort},
      {bad_magic, DatagramError::kMagic},
      {{0x4c, 0x43, 0x30, 0x32, 0, 0, 0, 1}, DatagramError::kTooShort},
      {no_nul, DatagramError::kChannel},
      {small("", part), DatagramError::kChannel},
      {long_name, DatagramError::kChannel},
      {truncated, DatagramError::kTooShort},
      {fragment(1, 20, 0, 2, 2, "A", part), DatagramError::kFragment},         // number >= count
      {fragment(1, 20, 0, 0, 0, "A", part), DatagramError::kFragment},         // no fragments
      {fragment(1, 20, 5, 0, 2, "A", part), DatagramError::kFragment},         // first not at 0
      {fragment(1, 5, 0, 0, 2, "A", part), DatagramError::kFragment},          // more data than the message
      {fragment(1, 2u << 20, 0, 0, 40, "A", part), DatagramError::kTooLarge},  // over the limit
  };
  int64_t n = 0;
  for (const auto& c : cases) {
    EXPECT_EQ(f(3, c.d), c.e) << "case " << n;
    EXPECT_FALSE(f.complete) << "case " << n;
    EXPECT_EQ(f.r.counters().rejected, ++n);
  }
  // Inside a message: a repeated fragment, and one reaching past its end.
  EXPECT_EQ(f(3, fragment(9, 30, 0, 0, 3, "A", part)), DatagramError::kNone);
  EXPECT_EQ(f(3, fragment(9, 30, 10, 1, 3, "", part)), DatagramError::kNone);
  EXPECT_EQ(f(3, fragment(9, 30, 10, 1, 3, "", part)), DatagramError::kFragment);
  EXPECT_EQ(f(3, fragment(9, 30, 25, 2, 3, "", part)), DatagramError::kFragment);
  EXPECT_EQ(f(3, fragment(9, 30, 20, 2, 4, "", part)), DatagramError::kFragment);  // count changed
  EXPECT_FALSE(f.complete);
  EXPECT_EQ(f(3, fragment(9, 30, 20, 2, 3, "", part)), DatagramError::kNone);
  EXPECT_TRUE(f.complete);  // the good fragments still make the message
}

TEST(LcmDatagram, ManySendersHoldBoundedMemory) {
  // A flood of first fragments from many ports: at most a bounded number stay pending, the rest
  // are abandoned (counted), and a later sender's message still completes.
  Feed f;
  const auto part = bytes(100, 1);
  for (uint64_t s = 0; s < 1000; ++s)
    EXPECT_EQ(f(s, fragment(1, 1000, 0, 0, 10, "A", part)), DatagramError::kNone);
  EXPECT_EQ(f.r.counters().incomplete, 1000 - static_cast<int64_t>(LcmReassembler::kMaxPending));
  EXPECT_EQ(f(5000, small("B", part)), DatagramError::kNone);
  EXPECT_TRUE(f.complete);
}

TEST(LcmDatagram, ClaimedSizesCannotHoldMoreThanTheBudget) {
  // Each sender claims the largest message allowed and never sends the rest: the reassembler
  // keeps at most 64 MiB (or twice the limit), abandoning the oldest, and a real message from a
  // sender already pending still completes.
  LcmReassembler r(32u << 20);
  LcmMessageView m;
  bool complete = false;
  const auto part = bytes(1000, 2);
  for (uint64_t s = 0; s < 20; ++s) {
    const auto d = fragment(1, 32u << 20, 0, 0, 600, "HUGE", part);
    ASSERT_EQ(r.feed(s, d.data(), d.size(), &m, &complete), DatagramError::kNone);
    EXPECT_LE(r.pending_bytes(), std::size_t{64} << 20);
  }
  EXPECT_EQ(r.counters().incomplete, 18);
  const auto p = bytes(1500, 4);
  const std::vector<uint8_t> a(p.begin(), p.begin() + 1000), b(p.begin() + 1000, p.end());
  auto d = fragment(2, 1500, 0, 0, 2, "REAL", a);
  ASSERT_EQ(r.feed(19, d.data(), d.size(), &m, &complete), DatagramError::kNone);  // abandons 18's
  d = fragment(2, 1500, 1000, 1, 2, "", b);
  ASSERT_EQ(r.feed(19, d.data(), d.size(), &m, &complete), DatagramError::kNone);
  ASSERT_TRUE(complete);
  EXPECT_EQ(std::vector<uint8_t>(m.data, m.data + m.size), p);
  EXPECT_EQ(r.pending_bytes(), std::size_t{32} << 20);  // sender 19's own claim is all that is left
}
