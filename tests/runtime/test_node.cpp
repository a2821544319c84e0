// The node runtime over memq:// (one process, publish and handle on the same LCM object).
#include <gtest/gtest.h>
#include <unistd.h>
#include <chrono>

#include <fstream>
#include <limits>
#include <random>
#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/controller_status_t.hpp>
#include <semx/path_t.hpp>
#include <semx/sim_event_t.hpp>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/node.hpp"
#include "semx/runtime/wire_generator.hpp"

using namespace semx::runtime;

namespace {

NodeOptions memq(const std::string& name, bool lockstep = false) {
  NodeOptions o;
  o.name = name;
  o.lcm_url = "memq://";
  o.lockstep = lockstep;
  o.status_period_s = 1000;  // heartbeats only when a test asks
  o.quiet = true;
  return o;
}

void drain(Node& n) { n.drain(); }

// SIM_CLOCK tick k (10 ms apart) in LOCKSTEP, handled.
void lockstep_tick(Node& n, int64_t k) {
  semx::clock_t c{};
  c.utime = k * 10000;
  c.tick = k;
  c.mode = semx::clock_t::LOCKSTEP;
  n.publish("SIM_CLOCK", c);
  drain(n);
}

semx::odometry_t odom(double x) {
  semx::odometry_t m{};
  m.utime = 1;
  m.position[0] = x;
  m.orientation[0] = 1;
  return m;
}

int64_t rss_kb() {
  std::ifstream statm("/proc/self/statm");
  long total = 0, resident = 0;
  statm >> total >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

// A launched node repeats its first NODE_STATUS a few times within a second (the lockstep
// simulator waits to hear it), then keeps to its heartbeat period.
TEST(Node, AnnouncesItselfAFewTimesAfterStarting) {
  for (const bool announce : {false, true}) {
    NodeOptions o = memq("announcer");
    o.announce = announce;
    Node n(o);
    int statuses = 0;
    n.subscribe<semx::node_status_t>("NODE_STATUS", [&](const semx::node_status_t&) { ++statuses; });
    // Statuses at 0, 0.05, 0.15, 0.35 and 0.75 s with announce; the next one 1000 s later.
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
    while (std::chrono::steady_clock::now() < end) n.spin_once(10);
    EXPECT_EQ(statuses, announce ? 5 : 1) << "announce " << announce;
  }
}

TEST(Node, TypedRoundTripIsCounted) {
  Node n(memq("t"));
  std::vector<double> xs;
  n.subscribe<semx::odometry_t>("ODOMETRY", [&](const semx::odometry_t& m) { xs.push_back(m.position[0]); });
  ASSERT_TRUE(n.publish("ODOMETRY", odom(1.5)));
  ASSERT_TRUE(n.publish("ODOMETRY", odom(2.5)));
  drain(n);
  EXPECT_EQ(xs, (std::vector<double>{1.5, 2.5}));
  EXPECT_EQ(n.incoming().at("ODOMETRY").bytes, n.outgoing().at("ODOMETRY").bytes);
  EXPECT_EQ(n.incoming().at("ODOMETRY").messages, 2);
  EXPECT_EQ(n.outgoing().at("ODOMETRY").messages, 2);
}

TEST(Node, HostileBytesAreCountedDroppedAndNeverReachTheHandler) {
  Node n(memq("victim"));
  int delivered = 0;
  n.subscribe<semx::path_t>("PLAN_PATH", [&](const semx::path_t&) { ++delivered; });
  const auto& schema = LcmSchema::semx();
  const auto& type = *schema.find("semx.path_t");
  std::mt19937_64 rng(3);
  const int64_t rss_before = rss_kb();
  int sent = 0;
  for (auto kind : {HostileKind::kTruncated, HostileKind::kOversized, HostileKind::kNegativeLength,
                    HostileKind::kHugeLength, HostileKind::kWrongFingerprint}) {
    for (int i = 0; i < 20; ++i) {
      const auto bytes = hostile_wire_message(schema, type, kind, rng);
      n.publish_raw("PLAN_PATH", bytes.data(), bytes.size());
      ++sent;
    }
  }
  drain(n);
  EXPECT_EQ(delivered, 0);
  EXPECT_EQ(n.counters().malformed, sent);
  EXPECT_EQ(n.incoming().at("PLAN_PATH").malformed, sent);
  // A decoder trusting the huge lengths would have tried to reserve gigabytes.
  EXPECT_LT(rss_kb() - rss_before, 20 * 1024);

  // Still alive and serving.
  semx::path_t good{};
  good.num_waypoints = 1;
  good.waypoints = {{1, 2, 3}};
  good.yaws = {0.5};
  n.publish("PLAN_PATH", good);
  drain(n);
  EXPECT_EQ(delivered, 1);
}

// No handler sees a NaN or an inf, whichever field and whatever the subscriber checks itself:
// an evaluator without a check on SIM_EVENT once counted a COLLISION at (nan, inf, 1e300).
TEST(Node, NonFiniteValuesNeverReachAHandler) {
  Node n(memq("victim"));
  int events = 0, statuses = 0;
  n.subscribe<semx::sim_event_t>("SIM_EVENT", [&](const semx::sim_event_t&) { ++events; });
  n.subscribe<semx::controller_status_t>("CONTROLLER_STATUS", [&](const semx::controller_status_t&) { ++statuses; });
  semx::sim_event_t e{};
  e.type = semx::sim_event_t::COLLISION;
  e.count = 1;
  n.publish("SIM_EVENT", e);
  e.position[1] = std::numeric_limits<double>::infinity();
  n.publish("SIM_EVENT", e);
  semx::controller_status_t c{};
  c.progress = std::nan("");
  n.publish("CONTROLLER_STATUS", c);
  drain(n);
  EXPECT_EQ(events, 1);
  EXPECT_EQ(statuses, 0);
  EXPECT_EQ(n.counters().malformed, 2);
}

TEST(Node, ContentCheckRejectsAsMalformed) {
  Node n(memq("t"));
  int delivered = 0;
  n.subscribe<semx::odometry_t>(
      "ODOMETRY", [&](const semx::odometry_t&) { ++delivered; },
      [](const semx::odometry_t& m) { return std::isfinite(m.position[0]); });
  n.publish("ODOMETRY", odom(std::nan("")));
  n.publish("ODOMETRY", odom(1));
  drain(n);
  EXPECT_EQ(delivered, 1);
  EXPECT_EQ(n.counters().malformed, 1);
}

TEST(Node, OversizedMessagesAreDroppedUnread) {
  auto o = memq("t");
  o.max_message_bytes = 1000;
  Node n(o);
  int delivered = 0;
  n.subscribe<semx::path_t>("PLAN_PATH", [&](const semx::path_t&) { ++delivered; });
  semx::path_t big{};
  big.num_waypoints = 100;
  big.waypoints.assign(100, std::vector<double>(3, 0.0));
  big.yaws.assign(100, 0.0);
  n.publish("PLAN_PATH", big);
  drain(n);
  EXPECT_EQ(delivered, 0);
  EXPECT_EQ(n.counters().dropped, 1);
  EXPECT_EQ(n.counters().malformed, 0);
}

TEST(Node, SkipFilterDropsByUtimeBeforeDecoding) {
  Node n(memq("t"));
  std::vector<int64_t> delivered;
  n.subscribe<semx::odometry_t>("ODOMETRY", [&](const semx::odometry_t& m) { delivered.push_back(m.utime); });
  std::vector<int64_t> asked;
  n.skip_unless("ODOMETRY", [&](int64_t utime) {
    asked.push_back(utime);
    return utime % 2 == 0;
  });
  for (int64_t t : {2, 3, 4, -5}) {
    auto m = odom(1.0);
    m.utime = t;
    n.publish("ODOMETRY", m);
  }
  const uint8_t garbage[12] = {1, 2, 3};  // too short to hold a utime: the normal checks apply
  n.publish_raw("ODOMETRY", garbage, sizeof garbage);
  drain(n);
  EXPECT_EQ(asked, (std::vector<int64_t>{2, 3, 4, -5}));
  EXPECT_EQ(delivered, (std::vector<int64_t>{2, 4}));
  const ChannelCounters& c = n.incoming().at("ODOMETRY");
  EXPECT_EQ(c.messages, 5);
  EXPECT_EQ(c.skipped, 2);
  EXPECT_EQ(c.malformed, 1);
}

TEST(Node, HandlerExceptionsAreCaughtAndCounted) {
  Node n(memq("t"));
  n.subscribe<semx::odometry_t>("ODOMETRY", [](const semx::odometry_t&) { throw std::runtime_error("bug"); });
  n.publish("ODOMETRY", odom(1));
  n.publish("ODOMETRY", odom(2));
  drain(n);
  EXPECT_EQ(n.counters().handler_errors, 2);
  EXPECT_GE(n.spin_once(0), 0) << "the LCM object is still usable after a throwing handler";
}

TEST(Node, LockstepNodeDoesTickWorkThenAcks) {
  Node n(memq("mapper", true));
  std::vector<std::string> order;
  n.on_tick([&](int64_t tick, int64_t) {
    order.push_back("work" + std::to_string(tick));
    n.publish("ODOMETRY", odom(static_cast<double>(tick)));
  });
  n.subscribe<semx::ack_t>("SIM_ACK", [&](const semx::ack_t& a) {
    EXPECT_EQ(a.node, "mapper");
    order.push_back("ack" + std::to_string(a.tick));
  });
  n.subscribe<semx::odometry_t>("ODOMETRY", [&](const semx::odometry_t&) { order.push_back("out"); });
  for (int64_t tick : {0, 1, 1, 2}) lockstep_tick(n, tick);
  EXPECT_EQ(order, (std::vector<std::string>{"work0", "out", "ack0", "work1", "out", "ack1", "ack1", "work2",
                                             "out", "ack2"}));
  EXPECT_EQ(n.now_utime(), 20000);
}

TEST(Node, WithinItsPromiseANodeAcksOnlyEvery50msAndRunsDeferredWorkAfterTheAck) {
  Node n(memq("planner", true));
  int64_t promise = 0;  // what the node says at each ack
  n.on_quiet_until([&](int64_t) { return promise; });
  std::vector<std::string> order;
  n.on_tick([&](int64_t tick, int64_t) {
    if (tick == 2) {
      n.after_ack([&] {
        order.push_back("work2 after " + std::to_string(n.outgoing().at("SIM_ACK").messages) + " acks");
      });
    }
  });
  n.subscribe<semx::ack_t>("SIM_ACK",
                           [&](const semx::ack_t& a) { order.push_back("ack" + std::to_string(a.tick)); });
  auto tick = [&](int64_t k) { lockstep_tick(n, k); };
  tick(0);
  tick(1);
  promise = 250000;  // quiet until 0.25 s, said with the ack of tick 2
  tick(2);
  for (int64_t k = 3; k <= 26; ++k) tick(k);
  tick(26);  // the clock resends a tick it waits for: always acked
  // Ticks 3-6 and 8-11 fall inside the promise and within 50 ms of the last ack; 7 and 12 are
  // 50 ms after one; from 25 (0.25 s) on the promise is over and every tick is acked.
  EXPECT_EQ(order, (std::vector<std::string>{"ack0", "ack1", "work2 after 3 acks", "ack2", "ack7", "ack12",
                                             "ack17", "ack22", "ack25", "ack26", "ack26"}));
}

TEST(Node, StatusCarriesCountersAndState) {
  Node n(memq("statusy"));
  std::vector<semx::node_status_t> seen;
  n.subscribe<semx::node_status_t>("NODE_STATUS", [&](const semx::node_status_t& s) { seen.push_back(s); });
  const std::vector<uint8_t> junk{1, 2, 3};
  n.publish_raw("NODE_STATUS", junk.data(), junk.size());
  drain(n);
  n.set_state(NodeState::kDegraded, "testing");
  drain(n);
  ASSERT_FALSE(seen.empty());
  const auto& s = seen.back();
  EXPECT_EQ(s.node, "statusy");
  EXPECT_EQ(s.pid, getpid());
  EXPECT_EQ(s.state, static_cast<int8_t>(NodeState::kDegraded));
  EXPECT_EQ(s.detail, "testing");
  EXPECT_EQ(s.malformed, 1);
  EXPECT_GT(s.rss_kb, 0);
  EXPECT_EQ(s.num_channels, static_cast<int32_t>(s.channels.size()));
}

TEST(Node, BadUrlIsAClearError) {
  auto o = memq("t");
  o.lcm_url = "bogus://nowhere";
  EXPECT_THROW({ Node n(o); }, NodeError);
}
