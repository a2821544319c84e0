// Lossless delivery (delivery.hpp): gaps and lost last messages are noticed, asked for, filled in
// the publisher's order; what never comes is given up and counted.
#include <gtest/gtest.h>

#include "semx/runtime/delivery.hpp"

using namespace semx::runtime;

namespace {

constexpr uint64_t kSelf = 1, kMapper = 7;
const StreamKey kMap{kMapper, 42};
const uint8_t kByte = 0;

Inbox::Arrival arrive(Inbox& in, uint32_t seq, double now = 0) {
  const uint8_t b[1] = {static_cast<uint8_t>(seq)};
  return in.arrive(kMap, seq, "MAP_UPDATE", b, 1, now);
}

std::vector<int> drain(Inbox& in) {
  std::vector<int> out;
  Inbox::Ready r;
  while (in.ready(&r)) out.push_back(r.bytes.at(0));
  return out;
}

}  // namespace

TEST(Delivery, InOrderMessagesPassAndDuplicatesAreDropped) {
  Inbox in(kSelf);
  in.reads(42);
  EXPECT_TRUE(in.tick({}, 0));
  EXPECT_EQ(arrive(in, 1), Inbox::Arrival::kDeliver);
  EXPECT_EQ(arrive(in, 2), Inbox::Arrival::kDeliver);
  EXPECT_EQ(arrive(in, 2), Inbox::Arrival::kDuplicate);
  EXPECT_TRUE(in.complete());
  EXPECT_TRUE(in.requests(1.0).empty());
  (void)kByte;
}

TEST(Delivery, AGapIsAskedForAndItsFollowersWaitForIt) {
  Inbox in(kSelf);
  in.reads(42);
  in.tick({}, 0);
  EXPECT_EQ(arrive(in, 1), Inbox::Arrival::kDeliver);
  EXPECT_EQ(arrive(in, 4, 0.0), Inbox::Arrival::kHeld);  // 2 and 3 lost
  EXPECT_EQ(arrive(in, 5, 0.0), Inbox::Arrival::kHeld);
  EXPECT_FALSE(in.complete());
  auto q = in.requests(0.0);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].stream.sender, kMapper);
  EXPECT_EQ(q[0].first, 2u);
  EXPECT_EQ(q[0].last, 3u);  // the held ones are not asked for
  EXPECT_TRUE(in.requests(0.01).empty());     // not again at once
  EXPECT_EQ(in.requests(0.1).size(), 1u);    // but again after retry_s
  EXPECT_EQ(arrive(in, 3), Inbox::Arrival::kHeld);
  EXPECT_EQ(arrive(in, 2), Inbox::Arrival::kDeliver);
  EXPECT_EQ(drain(in), (std::vector<int>{3, 4, 5}));
  EXPECT_TRUE(in.complete());
  EXPECT_EQ(in.counters().recovered, 1);
  EXPECT_EQ(in.held_bytes(), 0u);
}

TEST(Delivery, ATickNamesALostLastMessage) {
  Inbox in(kSelf);
  in.reads(42);
  in.tick({}, 0);
  arrive(in, 1);
  // Nothing follows message 2 on its channel; the tick's heads tell.
  EXPECT_FALSE(in.tick({{kMap, 2}}, 0.0));
  auto q = in.requests(0.0);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].first, 2u);
  EXPECT_EQ(q[0].last, 2u);
  EXPECT_EQ(arrive(in, 2), Inbox::Arrival::kDeliver);
  EXPECT_TRUE(in.complete());
  // Heads of channels it does not read, and of itself, ask for nothing.
  EXPECT_TRUE(in.tick({{{kMapper, 99}, 5}, {{kSelf, 42}, 9}}, 1.0));
}

TEST(Delivery, AReaderThereFromTheStartIsOwedEverything) {
  Inbox in(kSelf);
  in.reads(42);
  // The first frame was lost before the first tick: the tick's heads name it.
  EXPECT_FALSE(in.tick({{kMap, 1}}, 0));
  ASSERT_EQ(in.requests(0).size(), 1u);
  EXPECT_EQ(arrive(in, 1), Inbox::Arrival::kDeliver);
  EXPECT_TRUE(in.complete());
  // And a stream first heard at its 3rd message misses the first two.
  const StreamKey other{kMapper + 5, 42};
  const uint8_t b[1] = {3};
  EXPECT_EQ(in.arrive(other, 3, "MAP_UPDATE", b, 1, 0), Inbox::Arrival::kHeld);
}

TEST(Delivery, ManyGapsInOneStreamAreAllAskedForAtOnce) {
  Inbox in(kSelf);
  in.reads(42);
  in.tick({}, 0);
  arrive(in, 1);
  for (uint32_t seq : {3u, 5u, 6u, 9u}) arrive(in, seq, 0.0);
  auto q = in.requests(0.0);
  ASSERT_EQ(q.size(), 3u);  // 2, 4, 7..8
  EXPECT_EQ(q[0].first, 2u);
  EXPECT_EQ(q[1].first, 4u);
  EXPECT_EQ(q[2].first, 7u);
  EXPECT_EQ(q[2].last, 8u);
  // A new gap is asked for at once; the old ones only after retry_s.
  arrive(in, 12, 0.01);
  q = in.requests(0.01);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].first, 10u);
  EXPECT_EQ(q[0].last, 11u);
  EXPECT_EQ(in.requests(0.1).size(), 4u);
}

TEST(Delivery, WhatCameBeforeALateReaderStartedIsNotMissing) {
  Inbox::Options late;
  late.from_start = false;  // a respawned node, an observer
  Inbox in(kSelf, late);
  in.reads(42);
  // Its first tick: the mapper had sent 10 messages before this reader existed.
  EXPECT_TRUE(in.tick({{kMap, 10}}, 0));
  EXPECT_EQ(arrive(in, 11), Inbox::Arrival::kDeliver);
  // A publisher that appears later (a respawned mapper: a new sender) owes it everything from 1.
  const StreamKey respawned{kMapper + 1, 42};
  EXPECT_FALSE(in.tick({{kMap, 11}, {respawned, 2}}, 1.0));
  auto q = in.requests(1.0);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].first, 1u);
  EXPECT_EQ(q[0].last, 2u);
  // A channel read only from now on starts at its publishers' current heads.
  in.reads(43);
  EXPECT_FALSE(in.tick({{{kMapper, 43}, 30}, {respawned, 2}}, 1.0));
  const uint8_t b[1] = {1};
  in.arrive(respawned, 1, "MAP_UPDATE", b, 1, 1.0);
  in.arrive(respawned, 2, "MAP_UPDATE", b, 1, 1.0);
  EXPECT_TRUE(in.complete());
}

TEST(Delivery, WhatNeverComesIsGivenUpAndCounted) {
  Inbox in(kSelf, {0.05, 2.0, 64u << 20, true});
  in.reads(42);
  in.tick({}, 0);
  arrive(in, 1);
  arrive(in, 3, 10.0);
  arrive(in, 6, 10.0);
  EXPECT_TRUE(in.give_up(11.0).empty());  // not yet
  EXPECT_FALSE(in.complete());
  const auto lost = in.give_up(12.5);  // 2, then 4 and 5
  ASSERT_EQ(lost.size(), 2u);
  EXPECT_EQ(lost[0].first, 2u);
  EXPECT_EQ(lost[0].last, 2u);
  EXPECT_EQ(lost[1].first, 4u);
  EXPECT_EQ(lost[1].last, 5u);
  EXPECT_EQ(drain(in), (std::vector<int>{3, 6}));
  EXPECT_TRUE(in.complete());
  EXPECT_EQ(in.counters().lost, 3);
  EXPECT_EQ(arrive(in, 7), Inbox::Arrival::kDeliver);
  EXPECT_EQ(arrive(in, 4), Inbox::Arrival::kDuplicate);  // too late
}

TEST(Delivery, HistoryKeepsTheLastMessagesOfEachChannel) {
  ResendHistory h(3, 1000);
  for (uint32_t seq = 1; seq <= 5; ++seq) h.keep("ODOMETRY", 5, seq, std::vector<uint8_t>(10, static_cast<uint8_t>(seq)));
  const std::string* channel = nullptr;
  EXPECT_EQ(h.find(5, 2, &channel), nullptr);
  const auto* m = h.find(5, 4, &channel);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->at(0), 4);
  EXPECT_EQ(*channel, "ODOMETRY");
  EXPECT_EQ(h.find(6, 4, &channel), nullptr);
  // A byte budget: big messages are kept fewer, but the last one always.
  h.keep("CAMERA_DEPTH", 9, 1, std::vector<uint8_t>(600));
  h.keep("CAMERA_DEPTH", 9, 2, std::vector<uint8_t>(600));
  EXPECT_EQ(h.find(9, 1, &channel), nullptr);
  EXPECT_NE(h.find(9, 2, &channel), nullptr);
  EXPECT_EQ(h.bytes(), 3 * 10 + 600u);
}
