// FrameGate: which frames a node processes (semantics detector.frame_period_s, mapper
// integration.frame_period_s).
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "semx/runtime/frame_gate.hpp"

using semx::runtime::FrameGate;

namespace {

// Feeds frames at the given utimes, taking every due one; returns those taken.
std::vector<int64_t> taken(FrameGate& g, const std::vector<int64_t>& utimes) {
  std::vector<int64_t> out;
  for (int64_t t : utimes) {
    if (!g.due(t)) continue;
    g.taken(t);
    out.push_back(t);
  }
  return out;
}

}  // namespace

TEST(FrameGate, ThirtyHertzOnTheTickGridBecomesTenHertz) {
  FrameGate g(0.1);
  // The simulator's 30 Hz camera on its 10 ms ticks: 0, 40, 70, 100, 140, 170, 200, ... ms.
  std::vector<int64_t> frames;
  for (int k = 0; k < 31; ++k) frames.push_back((k * 100000 / 3 + 9999) / 10000 * 10000);
  EXPECT_EQ(taken(g, frames), (std::vector<int64_t>{0, 100000, 200000, 300000, 400000, 500000, 600000, 700000,
                                                    800000, 900000, 1000000}));
}

TEST(FrameGate, MicrosecondRoundingDoesNotHalveTheRate) {
  FrameGate g(0.1);
  std::vector<int64_t> frames;
  for (int k = 0; k < 10; ++k) frames.push_back(k * 33333);  // 99999 is the 0.1 s frame
  EXPECT_EQ(taken(g, frames), (std::vector<int64_t>{0, 99999, 199998, 299997}));
}

TEST(FrameGate, LateFramesRestartTheScheduleAndANewEpisodeIsDue) {
  FrameGate g(0.1);
  EXPECT_EQ(taken(g, {0, 50000, 350000, 400000, 450000}), (std::vector<int64_t>{0, 350000, 450000}));
  EXPECT_TRUE(g.due(10000)) << "time went backwards: a new episode";
  g.taken(10000);
  EXPECT_FALSE(g.due(60000));
  EXPECT_TRUE(g.due(110000));
}

TEST(FrameGate, PeriodZeroTakesEveryFrame) {
  FrameGate g(0.0);
  EXPECT_EQ(taken(g, {0, 1, 2, 33333}), (std::vector<int64_t>{0, 1, 2, 33333}));
}

TEST(FrameGate, NextDueIsTheEarliestFrameItWouldTake) {
  FrameGate g(0.1);
  EXPECT_EQ(g.next_due(), std::numeric_limits<int64_t>::min()) << "before the first frame, any";
  for (int64_t taken_at : {0, 99999, 240000}) {
    g.taken(taken_at);
    // A node promises quiet until next_due(): no frame before it may be due.
    for (int64_t t = taken_at; t < taken_at + 300000; t += 500) EXPECT_EQ(g.due(t), t >= g.next_due()) << t;
  }
}
