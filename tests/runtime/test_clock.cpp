#include <gtest/gtest.h>

#include <limits>

#include "semx/runtime/clock_server.hpp"
#include "semx/runtime/sim_clock.hpp"

using namespace semx::runtime;

TEST(SimClock, NewTicksRunWorkAndAckOnlyInLockstep) {
  SimClock participant(true), observer(false);
  auto d = participant.on_clock(0, 0, ClockMode::kLockstep);
  EXPECT_TRUE(d.new_tick);
  EXPECT_TRUE(d.ack);
  d = observer.on_clock(0, 0, ClockMode::kLockstep);
  EXPECT_TRUE(d.new_tick);
  EXPECT_FALSE(d.ack);
  d = participant.on_clock(1, 10000, ClockMode::kRealtime);
  EXPECT_TRUE(d.new_tick);
  EXPECT_FALSE(d.ack) << "nobody acks a realtime clock";
  EXPECT_EQ(participant.now_utime(), 10000);
}

TEST(SimClock, ResentTickIsReackedWithoutWork) {
  SimClock c(true);
  c.on_clock(5, 50000, ClockMode::kLockstep);
  const auto d = c.on_clock(5, 50000, ClockMode::kLockstep);
  EXPECT_FALSE(d.new_tick);
  EXPECT_TRUE(d.ack);
}

TEST(SimClock, StaleTicksAreIgnoredAndTickZeroResets) {
  SimClock c(true);
  c.on_clock(5, 50000, ClockMode::kLockstep);
  auto d = c.on_clock(3, 30000, ClockMode::kLockstep);
  EXPECT_FALSE(d.new_tick);
  EXPECT_FALSE(d.ack);
  EXPECT_EQ(c.now_utime(), 50000);
  d = c.on_clock(0, 0, ClockMode::kLockstep);
  EXPECT_TRUE(d.new_tick);
  EXPECT_TRUE(d.reset);
  EXPECT_EQ(c.now_utime(), 0);
  EXPECT_FALSE(c.on_clock(-1, 0, ClockMode::kLockstep).new_tick);
}

TEST(SimClock, TimeNeverRunsBackwardsWithinAnEpisode) {
  SimClock c;
  c.on_clock(1, 1000, ClockMode::kRealtime);
  c.on_clock(2, 500, ClockMode::kRealtime);
  EXPECT_EQ(c.now_utime(), 1000);
}

TEST(ClockServer, LockstepWaitsForEveryRegisteredNode) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"mapper", "planner"};
  cfg.resend_after_s = 1.0;
  ClockServer s(cfg);
  auto t = s.poll(0.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 0);
  EXPECT_FALSE(s.poll(0.1)) << "no acks yet";
  EXPECT_FALSE(s.on_ack("mapper", 0));
  EXPECT_FALSE(s.on_ack("stranger", 0));
  EXPECT_FALSE(s.on_ack("planner", 7)) << "an ack for another tick does not count";
  EXPECT_EQ(s.waiting_for(), std::vector<std::string>{"planner"});
  EXPECT_FALSE(s.poll(0.2));
  EXPECT_TRUE(s.on_ack("planner", 0));
  t = s.poll(0.2);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 1);
  EXPECT_EQ(t->utime, cfg.period_us);
  EXPECT_FALSE(t->resend);
}

TEST(ClockServer, LockstepResendsAStalledTick) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"late"};
  cfg.resend_after_s = 0.5;
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(0.0));
  EXPECT_FALSE(s.poll(0.4));
  auto t = s.poll(0.6);
  ASSERT_TRUE(t);
  EXPECT_TRUE(t->resend);
  EXPECT_EQ(t->tick, 0);
}

// A restarted clock source (the simulator after a crash) goes on from the tick it published
// last: it sends that tick again at once, waits for every node's ack of it, and never goes back.
TEST(ClockServer, ResumesAtItsLastTickAndWaitsForEveryAckAgain) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"mapper", "planner"};
  cfg.max_ticks = 500;
  cfg.resend_after_s = 1.0;
  ClockServer s(cfg);
  s.resume(420, 50.0);
  auto t = s.poll(50.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 420);
  EXPECT_EQ(t->utime, 420 * cfg.period_us);
  EXPECT_TRUE(t->resend) << "the nodes have had it: they ack it again without redoing it";
  EXPECT_FALSE(s.poll(50.1));
  EXPECT_FALSE(s.on_ack("mapper", 419)) << "an ack from before the crash does not count";
  EXPECT_FALSE(s.on_ack("mapper", 420));
  EXPECT_EQ(s.waiting_for(), std::vector<std::string>{"planner"});
  EXPECT_TRUE(s.on_ack("planner", 420));
  t = s.poll(50.2);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 421);
  EXPECT_FALSE(t->resend);
  EXPECT_FALSE(s.finished());
}

TEST(ClockServer, RealtimeResumeKeepsTheTickRate) {
  ClockServerConfig cfg;
  cfg.period_us = 10000;
  ClockServer s(cfg);
  s.resume(100, 7.0);
  EXPECT_FALSE(s.poll(7.005)) << "realtime does not resend";
  auto t = s.poll(7.0101);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 101);
}

TEST(ClockServer, RealtimeFollowsTheWallClockAtItsSpeed) {
  ClockServerConfig cfg;
  cfg.period_us = 10000;
  cfg.speed = 2.0;  // a 10 ms tick every 5 ms of wall time
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(100.0));
  EXPECT_FALSE(s.poll(100.004));
  auto t = s.poll(100.005);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 1);
}

TEST(ClockServer, StopsAfterMaxTicks) {
  ClockServerConfig cfg;
  cfg.max_ticks = 2;
  ClockServer s(cfg);
  EXPECT_TRUE(s.poll(0));
  EXPECT_TRUE(s.poll(1));
  EXPECT_TRUE(s.finished());
  EXPECT_FALSE(s.poll(2));
}

TEST(ClockServer, LockstepCanBeCappedToASpeed) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"a"};
  cfg.period_us = 10000;
  cfg.max_speed = 2.0;  // at most 2 simulated s per wall s: a tick every 5 ms
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(10.0));
  s.on_ack("a", 0);
  EXPECT_FALSE(s.poll(10.004)) << "acked, but faster than the cap";
  auto t = s.poll(10.005);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->tick, 1);
}

TEST(ClockServer, APromiseOfQuietIsNotWaitedForUntilItsTime) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"controller", "planner"};
  cfg.period_us = 10000;
  cfg.max_slack_us = 50000;
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(0.0));
  s.on_ack("controller", 0);
  // Quiet until t = 30 ms: ticks 1 and 2 go on without the planner, tick 3 waits for it.
  EXPECT_TRUE(s.on_ack("planner", 0, 30000));
  for (int64_t k = 1; k <= 3; ++k) {
    auto t = s.poll(0.0);
    ASSERT_TRUE(t) << "tick " << k;
    EXPECT_EQ(t->tick, k);
    EXPECT_TRUE(s.on_ack("controller", k) || k == 3);
  }
  EXPECT_FALSE(s.poll(0.0)) << "tick 3 is the planner's";
  EXPECT_EQ(s.waiting_for(), std::vector<std::string>{"planner"});
  // Its acks of the ticks it skipped come late and in order; the one of tick 3 completes it.
  EXPECT_FALSE(s.on_ack("planner", 1, 30000));
  EXPECT_FALSE(s.on_ack("planner", 2, 30000));
  EXPECT_TRUE(s.on_ack("planner", 3, 0));
  ASSERT_TRUE(s.poll(0.0));
  EXPECT_EQ(s.current_tick(), 4);
  EXPECT_FALSE(s.poll(0.0)) << "no promise now: tick 4 waits for both";
}

TEST(ClockServer, APromiseCountsAtMostTheSlackAhead) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"evaluator"};
  cfg.period_us = 10000;
  cfg.max_slack_us = 20000;
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(0.0));
  s.on_ack("evaluator", 0, std::numeric_limits<int64_t>::max());
  ASSERT_TRUE(s.poll(0.0));  // tick 1
  ASSERT_TRUE(s.poll(0.0));  // tick 2: tick 1 (10 ms) is within 0 + 20 ms
  EXPECT_EQ(s.current_tick(), 2);
  EXPECT_FALSE(s.poll(0.0)) << "tick 2 is as far as a node may fall behind";
  EXPECT_FALSE(s.on_ack("evaluator", 5, 0)) << "an ack from the future does not count";
  EXPECT_TRUE(s.on_ack("evaluator", 1, std::numeric_limits<int64_t>::max()));
  EXPECT_TRUE(s.poll(0.0));
}

TEST(ClockServer, CountsWhomItWaitedOnAndHowLong) {
  ClockServerConfig cfg;
  cfg.mode = ClockMode::kLockstep;
  cfg.lockstep_nodes = {"mapper", "planner"};
  ClockServer s(cfg);
  ASSERT_TRUE(s.poll(10.0));
  s.mark_published(10.5);  // the simulator stepped for 0.5 s before the tick went out
  EXPECT_FALSE(s.on_ack("mapper", 0, 0, 10.6));
  EXPECT_TRUE(s.on_ack("planner", 0, 0, 11.0));  // the last ack: 0.5 s after the tick went out
  ASSERT_TRUE(s.poll(11.0));
  s.mark_published(11.0);
  EXPECT_FALSE(s.on_ack("planner", 1, 0, 11.1));
  EXPECT_TRUE(s.on_ack("mapper", 1, 0, 11.25));
  ASSERT_EQ(s.waited_on().size(), 2u);
  EXPECT_NEAR(s.waited_on().at("planner"), 0.5, 1e-12);
  EXPECT_NEAR(s.waited_on().at("mapper"), 0.25, 1e-12);
  // Without a wall time nothing is counted.
  ASSERT_TRUE(s.poll(12.0));
  s.on_ack("planner", 2);
  s.on_ack("mapper", 2);
  EXPECT_NEAR(s.waited_on().at("mapper"), 0.25, 1e-12);
}
