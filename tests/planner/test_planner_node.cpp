// The planner node over memq:// (one process, one LCM object: the test publishes the inputs on
// the node's own LCM and listens to its outputs there): map from a MAP_SNAPSHOT, odometry, clock
// ticks in; PLAN_PATH, ROADMAP and PLANNER_STATUS out; malformed inputs counted and dropped.
#include <gtest/gtest.h>
#include <semx/clock_t.hpp>

#include <optional>
#include <vector>

#include "map_messages.hpp"
#include "planner_messages.hpp"
#include "planner_node.hpp"
#include "planner_test_util.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::planner {
namespace {

namespace ch = semx::channels;

runtime::NodeOptions memq() {
  runtime::NodeOptions o;
  o.name = "planner";
  o.lcm_url = "memq://";
  o.status_period_s = 1000;
  o.quiet = true;
  return o;
}

semx::odometry_t odometry(const Eigen::Vector3d& p, double yaw, int64_t utime) {
  semx::odometry_t m{};
  m.utime = utime;
  for (int i = 0; i < 3; ++i) m.position[i] = p[i];
  m.orientation[0] = std::cos(0.5 * yaw);
  m.orientation[3] = std::sin(0.5 * yaw);
  return m;
}

struct Harness {
  PlannerConfig config = test_config();
  std::unique_ptr<PlannerNode> planner;
  std::vector<semx::path_t> paths;
  std::vector<semx::roadmap_t> roadmaps;
  std::vector<semx::planner_status_t> statuses;
  int64_t tick = 0;

  explicit Harness(const std::string& kind = "semantic-dep") {
    config.planner = kind;
    planner = std::make_unique<PlannerNode>(memq(), config);
    runtime::Node& n = planner->node();
    n.subscribe<semx::path_t>(ch::PLAN_PATH, [this](const semx::path_t& m) { paths.push_back(m); });
    n.subscribe<semx::roadmap_t>(ch::ROADMAP, [this](const semx::roadmap_t& m) { roadmaps.push_back(m); });
    n.subscribe<semx::planner_status_t>(ch::PLANNER_STATUS,
                                        [this](const semx::planner_status_t& m) { statuses.push_back(m); });
  }
  runtime::Node& node() { return planner->node(); }
  void send_map(const map::StateGrid& g, int64_t seq = 1) {
    node().publish(ch::MAP_SNAPSHOT, map::to_message(map::encode_snapshot(g, seq, 0)));
    node().drain();
  }
  void send_pose(const Eigen::Vector3d& p, double yaw = 0.0) {
    node().publish(ch::ODOMETRY, odometry(p, yaw, tick * 10000));
    node().drain();
  }
  // Ticks of 10 ms.
  void run(int ticks) {
    for (int i = 0; i < ticks; ++i) {
      semx::clock_t c{};
      c.tick = tick;
      c.utime = tick * 10000;
      c.period_us = 10000;
      c.mode = semx::clock_t::REALTIME;
      c.speed = 1.0;
      node().publish(ch::SIM_CLOCK, c);
      node().drain();
      ++tick;
    }
  }
};

map::StateGrid corridor() {
  map::StateGrid g(0.1);
  SyntheticWorld::room({10, 4, 2.5}, {1, 2, 1.2})
      .reveal(g, {Eigen::Vector3d(-0.2, -0.2, -0.2), Eigen::Vector3d(6.0, 4.2, 2.7)});
  return g;
}

TEST(PlannerNode, PlansOnTheMapItReceivesAndPublishesEverything) {
  Harness h;
  h.run(3);
  ASSERT_FALSE(h.statuses.empty());  // INIT: waiting
  EXPECT_EQ(h.statuses.back().state, semx::planner_status_t::INIT);
  EXPECT_TRUE(h.paths.empty());
  const map::StateGrid g = corridor();
  h.send_map(g);
  ASSERT_TRUE(h.planner->map().in_sync());
  h.send_pose({1, 2, 1.2});
  h.run(100);
  ASSERT_FALSE(h.paths.empty());
  const semx::path_t& p = h.paths.front();
  EXPECT_EQ(p.plan_id, 1);
  EXPECT_EQ(p.num_waypoints, static_cast<int32_t>(p.waypoints.size()));
  EXPECT_EQ(p.yaws.size(), p.waypoints.size());
  EXPECT_DOUBLE_EQ(p.waypoints[0][0], 1.0);
  EXPECT_GT(p.waypoints.back()[0], 3.0);  // toward the frontier
  ASSERT_FALSE(h.roadmaps.empty());
  const semx::roadmap_t& r = h.roadmaps.back();
  EXPECT_EQ(r.num_nodes, static_cast<int32_t>(r.nodes.size()));
  EXPECT_GT(r.num_nodes, 10);
  EXPECT_EQ(r.edge_from.size(), r.edge_to.size());
  int roots = 0, goals = 0;
  for (const auto& n : r.nodes) {
    roots += (n.flags & semx::roadmap_node_t::ROOT) != 0;
    goals += (n.flags & semx::roadmap_node_t::GOAL) != 0;
  }
  EXPECT_EQ(roots, 1);
  EXPECT_EQ(goals, 1);
  const semx::planner_status_t& s = h.statuses.back();
  EXPECT_EQ(s.planner, "semantic-dep");
  EXPECT_EQ(s.state, semx::planner_status_t::EXECUTING);
  EXPECT_GT(s.iteration, 0);
  EXPECT_GT(s.charged_s, 0.0);
  EXPECT_GT(s.total_ms, 0.0);
  EXPECT_GT(s.best_gain, 0.0);
  // The status repeats at 1 Hz of message time even when nothing changes.
  const size_t before = h.statuses.size();
  h.run(300);
  EXPECT_GE(h.statuses.size(), before + 2);
}

TEST(PlannerNode, ReplansWhenTheControllerRejects) {
  Harness h;
  h.send_map(corridor());
  h.send_pose({1, 2, 1.2});
  h.run(100);
  ASSERT_EQ(h.paths.size(), 1u);
  semx::controller_status_t c{};
  c.utime = h.tick * 10000;
  c.plan_id = h.paths.back().plan_id;
  c.state = semx::controller_status_t::REJECTED;
  c.reason = "no safe trajectory";
  h.node().publish(ch::CONTROLLER_STATUS, c);
  h.node().drain();
  h.run(100);
  ASSERT_GE(h.paths.size(), 2u);
  EXPECT_EQ(h.paths[1].plan_id, 2);
}

TEST(PlannerNode, SemanticRegionsReachThePlanner) {
  Harness h;
  semx::semantic_regions_t m{};
  m.seq = 1;
  m.num_regions = 2;
  m.regions.resize(2);
  for (int i = 0; i < 2; ++i) {
    m.regions[i].id = i;
    m.regions[i].label = "chair";
    m.regions[i].centroid[0] = 3.0 + i;
    m.regions[i].weight = 10;
    m.regions[i].radius = 1.5;
    m.regions[i].active = i == 0;
  }
  h.node().publish(ch::SEMANTIC_REGIONS, m);
  h.node().drain();
  ASSERT_EQ(h.planner->planner().regions().size(), 2u);
  EXPECT_TRUE(h.planner->planner().regions()[0].active);
  EXPECT_FALSE(h.planner->planner().regions()[1].active);
  EXPECT_DOUBLE_EQ(h.planner->planner().regions()[1].centroid.x(), 4.0);
}

TEST(PlannerNode, MalformedInputsAreCountedAndDropped) {
  Harness h;
  const int64_t before = h.node().counters().malformed;
  const uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
  h.node().publish_raw(ch::ODOMETRY, junk, sizeof junk);
  h.node().publish_raw(ch::SEMANTIC_REGIONS, junk, sizeof junk);
  h.node().publish_raw(ch::CONTROLLER_STATUS, junk, sizeof junk);
  h.node().publish_raw(ch::MAP_UPDATE, junk, sizeof junk);
  semx::odometry_t bad = odometry({1, 2, 1.2}, 0.0, 0);
  bad.position[1] = NAN;
  h.node().publish(ch::ODOMETRY, bad);
  semx::odometry_t unnormalised = odometry({1, 2, 1.2}, 0.0, 0);
  unnormalised.orientation[0] = 2.0;
  h.node().publish(ch::ODOMETRY, unnormalised);
  semx::semantic_regions_t regions{};
  regions.num_regions = 1;
  regions.regions.resize(1);
  regions.regions[0].label = "x";
  regions.regions[0].radius = NAN;
  h.node().publish(ch::SEMANTIC_REGIONS, regions);
  semx::controller_status_t c{};
  c.reason = "?";
  c.state = 42;
  h.node().publish(ch::CONTROLLER_STATUS, c);
  h.node().drain();
  EXPECT_EQ(h.node().counters().malformed - before, 8);
  EXPECT_TRUE(h.planner->planner().regions().empty());
  // Nothing reached the planner: it still waits, and nothing crashed.
  h.send_map(corridor());
  h.run(50);
  EXPECT_TRUE(h.paths.empty());
  EXPECT_EQ(h.planner->planner().state(), PlannerState::kInit);
}

TEST(PlannerNode, ConversionsRoundTrip) {
  const semx::odometry_t m = odometry({1, 2, 3}, 2.5, 7);
  const VehiclePose p = to_pose(m);
  EXPECT_NEAR(p.yaw, 2.5, 1e-12);
  EXPECT_EQ(p.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(accept_odometry(m));
  PlannedPath path;
  path.plan_id = 4;
  path.waypoints = {{0, 0, 1}, {1, 0, 1}};
  path.yaws = {0.0, 0.5};
  const semx::path_t pm = to_message(path, 99);
  EXPECT_EQ(pm.num_waypoints, 2);
  EXPECT_EQ(pm.waypoints[1][0], 1.0);
  EXPECT_EQ(pm.yaws[1], 0.5);
  EXPECT_EQ(pm.utime, 99);
}

}  // namespace
}  // namespace semx::planner
