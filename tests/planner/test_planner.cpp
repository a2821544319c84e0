// The planner as a whole: goal choice on synthetic maps (the expected frontier, the semantically
// rewarded node), the main loop (termination, charged planning time, controller events), and
// whole explorations with every baseline (valid paths, no collisions, determinism).
#include <gtest/gtest.h>

#include <cmath>

#include "planner_test_util.hpp"
#include "semx/core/angles.hpp"
#include "semx/fixtures/exploration_sim.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/exploration_planner.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::planner {
namespace {

using map::VoxelState;

VehiclePose pose(const Eigen::Vector3d& p, double yaw = 0.0, int64_t utime = 0) {
  VehiclePose v;
  v.position = p;
  v.yaw = yaw;
  v.utime = utime;
  return v;
}

// Runs ticks every 10 ms from `from` until a path is released (or `until`); returns it.
std::optional<PlannedPath> first_path(ExplorationPlanner& p, int64_t from, int64_t until,
                                      int64_t* when = nullptr) {
  for (int64_t t = from; t <= until; t += 10000) {
    const auto out = p.tick(t);
    if (out.path) {
      if (when) *when = t;
      return out.path;
    }
  }
  return std::nullopt;
}

// A 10 x 4 x 2.5 m corridor whose first 6 m are known: the frontier is the plane x = 6.1.
map::StateGrid corridor() {
  map::StateGrid g(0.1);
  SyntheticWorld::room({10, 4, 2.5}, {1, 2, 1.2})
      .reveal(g, {Eigen::Vector3d(-0.2, -0.2, -0.2), Eigen::Vector3d(6.0, 4.2, 2.7)});
  return g;
}

TEST(Planner, PicksTheGoalFacingTheKnownFrontier) {
  map::StateGrid g = corridor();
  ExplorationPlanner p(test_config("dep"));
  p.set_map(&g);
  p.set_pose(pose({1, 2, 1.2}, 0.5 * core::kPi));
  const auto path = first_path(p, 0, 2000000);
  ASSERT_TRUE(path);
  const Goal& goal = p.goal();
  ASSERT_TRUE(goal.valid);
  EXPECT_GT(goal.position.x(), 3.5);                  // toward the frontier, clear of it
  EXPECT_LT(goal.position.x(), 6.1 - 0.45);           // in known free space with the clearance
  EXPECT_LT(core::yaw_distance(goal.yaw, 0.0), 0.4);  // looking at it
  EXPECT_EQ(path->waypoints.front(), Eigen::Vector3d(1, 2, 1.2));
  EXPECT_EQ(path->waypoints.back(), goal.position);
  EXPECT_EQ(path->yaws.size(), path->waypoints.size());
  EXPECT_NEAR(path->yaws.back(), goal.yaw, 1e-12);
  EXPECT_EQ(path->plan_id, 1);
  EXPECT_EQ(p.state(), PlannerState::kExecuting);
}

// Two nodes mirrored about x = 6 in a corridor with unknown space at both ends: equal gains.
struct MirrorScene : PlanScene {
  DepStrategy dep{config, true};
  int64_t left = -1, right = -1;

  MirrorScene() : PlanScene("semantic-dep") {
    SyntheticWorld::room({12, 4, 2.5}, {6, 2, 1.2})
        .reveal(grid, {Eigen::Vector3d(3.0, -0.2, -0.2), Eigen::Vector3d(8.95, 4.2, 2.7)});
    frontiers.reset(grid);
    dep.on_map_reset();
  }
  // A fresh strategy for the scene's config (after changing it) or plain DEP.
  void restart(bool semantic = true) {
    dep = DepStrategy(config, semantic);
    dep.on_map_reset();
  }
  Goal choose() {
    PlanContext ctx = context({6.0, 2.05, 1.25}, 0.5 * core::kPi);
    dep.process_map_changes(ctx);
    const int64_t root = dep.insert_root(ctx);
    dep.graph().node(root).blacklisted_until = 10;  // the choice is between the two nodes
    if (left < 0) left = dep.try_insert(ctx, {4.05, 2.05, 1.25});
    if (right < 0) right = dep.try_insert(ctx, {7.95, 2.05, 1.25});
    std::string reason;
    return dep.select_goal(ctx, dep.paper_score(), &reason);
  }
};

// R_sem of roadmap node `id` in the scene's last roadmap view.
double reward_of(MirrorScene& s, int64_t id) {
  for (const RoadmapView::Node& n : s.dep.roadmap(nullptr).nodes)
    if (n.id == id) return n.reward;
  ADD_FAILURE() << "node " << id << " not in the roadmap";
  return -1.0;
}

// Node `id`'s gain summed over every yaw bin (the U of the reward ablations).
double all_round_gain(MirrorScene& s, int64_t id) {
  double sum = 0.0;
  for (float b : s.dep.graph().node(id).gain.bin_gain) sum += b;
  return sum;
}

// A region 0.45 m from the scene's left node, nearest to it; it rewards that node
// kNearLeftReward by Eq. 6.
SemanticRegion near_left_region() {
  SemanticRegion r;
  r.centroid = Eigen::Vector3d(3.6, 2.05, 1.25);
  r.weight = 100.0;
  r.radius = 1.5;
  return r;
}
constexpr double kNearLeftReward = 100.0 * (1.0 - 0.45 / 1.5);

TEST(Planner, PicksTheSemanticallyRewardedOfTwoEqualNodes) {
  MirrorScene s;
  const Goal plain = s.choose();
  ASSERT_GE(s.left, 0);
  ASSERT_GE(s.right, 0);
  ASSERT_TRUE(plain.valid);
  const double gl = s.dep.graph().node(s.left).gain.gain, gr = s.dep.graph().node(s.right).gain.gain;
  ASSERT_GT(gl, 100.0);
  EXPECT_NEAR(gl, gr, 0.02 * gl);  // equal gains (mirror images)
  // A region beside one node, worth a fifth of the gain: that node wins, on either side.
  for (int side = 0; side < 2; ++side) {
    MirrorScene t;
    SemanticRegion r;
    r.centroid = Eigen::Vector3d(side == 0 ? 3.6 : 8.4, 2.05, 1.25);
    r.weight = 0.2 * gl / 0.7;  // R = w (1 - 0.45 / 1.5) = 0.2 G at the node
    r.radius = 1.5;
    t.regions = {r};
    const Goal g = t.choose();
    ASSERT_TRUE(g.valid);
    EXPECT_EQ(g.node, side == 0 ? t.left : t.right);
    EXPECT_NEAR(g.reward, 0.2 * gl, 1e-6 * gl);
    // The same region marked fully observed rewards nothing: the choice is the plain one again.
    MirrorScene u;
    r.active = false;
    u.regions = {r};
    EXPECT_EQ(u.choose().node, plain.node);
  }
  // Plain DEP ignores the regions.
  MirrorScene v;
  v.restart(false);
  SemanticRegion r;
  r.centroid = Eigen::Vector3d(plain.node == v.left ? 8.4 : 3.6, 2.05, 1.25);
  r.weight = 1e6;
  r.radius = 1.5;
  v.regions = {r};
  const Goal g = v.choose();
  EXPECT_EQ(g.reward, 0.0);
  EXPECT_EQ(g.position, plain.position);
}

// reward.unexplored_weight κ: a region's reward is multiplied by 1 + κ U, U the all-round gain of
// the roadmap node nearest its centroid; a region in mapped surroundings keeps the paper's reward.
TEST(Planner, UnexploredWeightScalesARegionByTheGainAroundIt) {
  const SemanticRegion r = near_left_region();
  const double paper = kNearLeftReward;

  MirrorScene plain;
  plain.regions = {r};
  plain.choose();
  ASSERT_GE(plain.left, 0);
  EXPECT_NEAR(reward_of(plain, plain.left), paper, 1e-9);

  MirrorScene scaled;
  scaled.config.reward.unexplored_weight = 1e-3;
  scaled.restart();
  scaled.regions = {r};
  scaled.choose();
  ASSERT_GE(scaled.left, 0);
  const double all_round = all_round_gain(scaled, scaled.left);
  ASSERT_GT(all_round, scaled.dep.graph().node(scaled.left).gain.gain);  // more than one window
  EXPECT_NEAR(reward_of(scaled, scaled.left), paper * (1.0 + 1e-3 * all_round), 1e-6 * paper);
  EXPECT_NEAR(reward_of(scaled, scaled.right), 0.0, 1e-12);  // out of the region's reach

  // Mapped all round: the nearest node sees nothing unknown, and the reward is the paper's.
  MirrorScene known;
  known.grid = map::StateGrid(0.1);
  SyntheticWorld::room({12, 4, 2.5}, {6, 2, 1.2})
      .reveal(known.grid, {Eigen::Vector3d(-0.2, -0.2, -0.2), Eigen::Vector3d(12.2, 4.2, 2.7)});
  known.frontiers.reset(known.grid);
  known.config.reward.unexplored_weight = 1e-3;
  known.restart();
  known.regions = {r};
  known.choose();
  ASSERT_GE(known.left, 0);
  EXPECT_NEAR(reward_of(known, known.left), paper, 1e-9);
}

// reward.passage_weight κ_p: a door rewards w (1 - d/r)(a + κ_p U), a = 1 while active, also once
// its leaf is fully observed; other classes keep the paper's reward, and κ_p = 0 is the paper's.
TEST(Planner, PassageWeightScalesADoorByTheGainAroundItEvenOnceObserved) {
  SemanticRegion door = near_left_region();
  door.class_id = static_cast<int>(runtime::SemanticClass::kDoor);
  const double paper = kNearLeftReward;
  SemanticRegion chair = door;
  chair.class_id = static_cast<int>(runtime::SemanticClass::kChair);

  for (bool active : {true, false}) {
    SCOPED_TRACE(active ? "active door" : "observed door");
    door.active = active;
    MirrorScene plain;
    plain.regions = {door};
    plain.choose();
    ASSERT_GE(plain.left, 0);
    EXPECT_NEAR(reward_of(plain, plain.left), active ? paper : 0.0, 1e-9);

    MirrorScene scaled;
    scaled.config.reward.passage_weight = 1e-3;
    scaled.restart();
    scaled.regions = {door};
    scaled.choose();
    ASSERT_GE(scaled.left, 0);
    const double all_round = all_round_gain(scaled, scaled.left);
    ASSERT_GT(all_round, 0.0);
    EXPECT_NEAR(reward_of(scaled, scaled.left), paper * ((active ? 1.0 : 0.0) + 1e-3 * all_round),
                1e-6 * paper);
  }

  MirrorScene other;  // not a door: the paper's reward whatever κ_p
  other.config.reward.passage_weight = 1e-3;
  other.restart();
  other.regions = {chair};
  other.choose();
  ASSERT_GE(other.left, 0);
  EXPECT_NEAR(reward_of(other, other.left), paper, 1e-9);
}

TEST(Planner, DeclaresDoneOnAFullyKnownMap) {
  const SyntheticWorld w = SyntheticWorld::two_rooms();
  map::StateGrid g = w.full_map();
  PlannerConfig c = test_config();
  ExplorationPlanner p(c);
  p.set_map(&g);
  p.set_pose(pose(w.start()));
  std::optional<StatusReport> last;
  for (int64_t t = 0; t < 10000000 && (p.state() != PlannerState::kDone || p.busy()); t += 10000) {
    const auto out = p.tick(t);
    EXPECT_FALSE(out.path);
    if (out.status) last = out.status;
  }
  ASSERT_EQ(p.state(), PlannerState::kDone);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->state, PlannerState::kDone);
  EXPECT_EQ(last->iteration, c.loop.done_cycles);
  EXPECT_NE(last->reason.find("no reachable node"), std::string::npos) << last->reason;
  EXPECT_NE(last->reason.find("0 frontier voxels"), std::string::npos) << last->reason;
  // Done is final.
  EXPECT_FALSE(p.tick(20000000).status);
}

TEST(Planner, ReportsInitUntilItHasMapAndPose) {
  map::StateGrid g = corridor();
  ExplorationPlanner p(test_config());
  auto out = p.tick(0);
  ASSERT_TRUE(out.status);
  EXPECT_EQ(out.status->state, PlannerState::kInit);
  EXPECT_EQ(out.status->reason, "waiting for the map");
  EXPECT_FALSE(p.tick(10000).status);  // once
  p.set_map(&g);
  EXPECT_FALSE(p.tick(20000).path);
  p.set_pose(pose({1, 2, 1.2}));
  EXPECT_TRUE(first_path(p, 30000, 2000000));
}

TEST(Planner, PlanningTimeIsChargedBeforeThePathGoesOut) {
  map::StateGrid g = corridor();
  PlannerConfig c = test_config();
  c.charge.base_s = 0.2;
  ExplorationPlanner p(c);
  p.set_map(&g);
  p.set_pose(pose({1, 2, 1.2}));
  auto out = p.tick(1000000);  // the cycle runs now ...
  EXPECT_FALSE(out.path);
  EXPECT_FALSE(out.status);
  EXPECT_TRUE(p.busy());
  EXPECT_EQ(p.state(), PlannerState::kPlanning);
  int64_t when = 0;
  const auto path = first_path(p, 1010000, 3000000, &when);  // ... its path comes after the charge
  ASSERT_TRUE(path);
  const double charged = p.last_status().charged_s;
  EXPECT_GE(charged, 0.2);
  EXPECT_GE(when, 1000000 + static_cast<int64_t>(charged * 1e6));
  EXPECT_LT(when, 1000000 + static_cast<int64_t>(charged * 1e6) + 10000);
  // The same work charges the same time: a second planner with the same seed agrees exactly.
  ExplorationPlanner q(c);
  q.set_map(&g);
  q.set_pose(pose({1, 2, 1.2}));
  int64_t when_q = 0;
  ASSERT_TRUE(first_path(q, 1000000, 3000000, &when_q));
  EXPECT_EQ(q.last_status().charged_s, charged);
  EXPECT_EQ(when_q, when);
  // Free planning: released in the same tick.
  c.charge.scale = 0.0;
  ExplorationPlanner r(c);
  r.set_map(&g);
  r.set_pose(pose({1, 2, 1.2}));
  EXPECT_TRUE(r.tick(0).path);
}

TEST(Planner, NoCycleIsChargedLessThanMinAndTheTwoStepTickAgrees) {
  map::StateGrid g = corridor();
  PlannerConfig c = test_config();
  c.charge.min_s = 2.0;  // far more than this cycle's work
  ExplorationPlanner p(c);
  p.set_map(&g);
  p.set_pose(pose({1, 2, 1.2}));
  int64_t when = 0;
  const auto path = first_path(p, 1000000, 5000000, &when);
  ASSERT_TRUE(path);
  EXPECT_DOUBLE_EQ(p.last_status().charged_s, 2.0);
  EXPECT_EQ(when, 3000000);
  // A node that acks the tick before the cycle (poll, then run_due_cycle after the ack) gets the
  // same path at the same tick, and can promise quiet for the least charge meanwhile.
  ExplorationPlanner q(c);
  q.set_map(&g);
  q.set_pose(pose({1, 2, 1.2}));
  EXPECT_EQ(q.min_charge_us(), 2000000);
  int64_t when_q = -1;
  std::optional<PlannedPath> path_q;
  for (int64_t t = 1000000; t <= 5000000 && !path_q; t += 10000) {
    bool due = false;
    const auto out = q.poll(t, due);
    if (out.path) {
      path_q = out.path;
      when_q = t;
    }
    if (due) {
      EXPECT_EQ(t, 1000000) << "one cycle, then its release";
      q.run_due_cycle(t);
      EXPECT_GE(q.quiet_until(t), t + q.min_charge_us());
    }
  }
  ASSERT_TRUE(path_q);
  EXPECT_EQ(when_q, when);
  EXPECT_EQ(path_q->waypoints, path->waypoints);
}

// The planner on the corridor map with the vehicle at (1, 2, 1.2), after its first path (at t).
struct CorridorStart {
  map::StateGrid g = corridor();
  ExplorationPlanner p{test_config()};
  int64_t t = 0;
  std::optional<PlannedPath> first;
  CorridorStart() {
    p.set_map(&g);
    p.set_pose(pose({1, 2, 1.2}));
    first = first_path(p, 0, 2000000, &t);
  }
};

TEST(Planner, ReplansWhenTheControllerRejectsAndAvoidsThatGoal) {
  CorridorStart start;
  auto& [g, p, t, first] = start;
  ASSERT_TRUE(first);
  const Goal rejected = p.goal();
  p.on_controller_status(ControllerState::kRejected, first->plan_id);
  const auto second = first_path(p, t + 10000, t + 2000000);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->plan_id, first->plan_id + 1);
  EXPECT_NE(p.goal().node, rejected.node);
  EXPECT_NE(p.last_status().reason.find("controller rejected"), std::string::npos) << p.last_status().reason;
}

TEST(Planner, ReplansWhenTheControllerStopsOnAPathItDidNotSend) {
  CorridorStart start;
  auto& [g, p, t, first] = start;
  ASSERT_TRUE(first);
  // Tracking someone else's path says nothing yet; a stop on it leaves the vehicle hovering, and
  // the planner plans again (before, it waited EXECUTING until the time limit).
  p.on_controller_status(ControllerState::kTracking, first->plan_id + 7);
  EXPECT_FALSE(first_path(p, t + 10000, t + 1000000)) << "nothing to replan for yet";
  p.on_controller_status(ControllerState::kRejected, first->plan_id + 7);
  const auto second = first_path(p, t + 1000000, t + 3000000);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->plan_id, first->plan_id + 1);
  EXPECT_NE(p.last_status().reason.find("did not send"), std::string::npos) << p.last_status().reason;
  // A status about one of its own earlier plans is history: nothing happens.
  p.on_controller_status(ControllerState::kRejected, first->plan_id);
  EXPECT_FALSE(first_path(p, t + 3000000, t + 4000000));
}

TEST(Planner, ReplansWhenARestartedControllerHasNoPath) {
  CorridorStart start;
  auto& [g, p, t, first] = start;
  ASSERT_TRUE(first);
  // Plan 0 right after the path went out: a status sent before the controller had it.
  p.on_controller_status(ControllerState::kIdle, 0, t + 100000);
  EXPECT_FALSE(first_path(p, t + 10000, t + 1000000)) << "nothing lost yet";
  // A second later the controller still has no path: it was restarted and lost ours.
  p.on_controller_status(ControllerState::kStaleInput, 0, t + 1000000 + 10000);
  const auto second = first_path(p, t + 1010000, t + 3000000);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->plan_id, first->plan_id + 1);
  EXPECT_NE(p.last_status().reason.find("no path"), std::string::npos) << p.last_status().reason;
}

TEST(Planner, GivesUpAGoalTheControllerHoldsShortOf) {
  CorridorStart start;
  auto& [g, p, t, first] = start;
  ASSERT_TRUE(first);
  const Goal unreachable = p.goal();
  ASSERT_GT((unreachable.position - Eigen::Vector3d(1, 2, 1.2)).norm(), p.config().loop.goal_tolerance);
  // The controller holds the path's end but the vehicle never left the start (its commands
  // rejected): the goal is given up after short_hold_s, not waited for forever.
  p.on_controller_status(ControllerState::kHolding, first->plan_id);
  const int64_t hold = static_cast<int64_t>(p.config().loop.short_hold_s * 1e6);
  EXPECT_FALSE(first_path(p, t + 10000, t + hold - 10000)) << "still waiting within short_hold_s";
  const auto second = first_path(p, t + hold, t + hold + 2000000);
  ASSERT_TRUE(second);
  EXPECT_NE(p.last_status().reason.find("controller holds short of the goal"), std::string::npos)
      << p.last_status().reason;
  EXPECT_NE(p.goal().node, unreachable.node);
}

TEST(Planner, AGoalReachedStartsACycleOnceTheDwellIsOverNotAtTheNextSlot) {
  // Cycles at 4 Hz, planning free (each cycle's outputs go out on its own tick).
  PlannerConfig c = test_config();
  c.charge.scale = 0.0;
  ExplorationPlanner p(c);
  map::StateGrid g = corridor();
  p.set_map(&g);
  p.set_pose(pose({1, 2, 1.2}));
  int64_t t = 0;
  const auto first = first_path(p, 0, 2000000, &t);
  ASSERT_TRUE(first);
  const Goal goal = p.goal();
  // The vehicle arrives 10 ms after the path, between two slots (t + k · 250 ms).
  const int64_t arrived = t + 10000;
  p.set_pose(pose(goal.position, goal.yaw, arrived));
  const int64_t dwell = static_cast<int64_t>(c.loop.dwell_s * 1e6);
  EXPECT_LE(p.quiet_until(arrived), arrived + dwell) << "the promise leaves room for the arrival";
  int64_t when = 0;
  const auto second = first_path(p, arrived, arrived + 2000000, &when);
  ASSERT_TRUE(second);
  EXPECT_NE(p.last_status().reason.find("goal reached"), std::string::npos) << p.last_status().reason;
  EXPECT_EQ(when, arrived + dwell) << "not at the slot after it, t + 500 ms";
}

TEST(Planner, ReplansWhenThePathIsBlocked) {
  CorridorStart start;
  auto& [g, p, t, first] = start;
  ASSERT_TRUE(first);
  ASSERT_GE(first->waypoints.size(), 2u);
  // An obstacle appears on the last segment of the path.
  const Eigen::Vector3d mid = 0.5 * (first->waypoints[first->waypoints.size() - 2] + first->waypoints.back());
  std::vector<map::VoxelChange> changes;
  const map::VoxelKey k = g.keys().key(mid);
  for (int dz = -1; dz <= 1; ++dz) {
    const map::VoxelKey q{k.x, k.y, k.z + dz};
    g.set_state(q, VoxelState::kOccupied);
    changes.push_back({q, VoxelState::kOccupied});
  }
  p.on_map_changes(changes);
  const auto second = first_path(p, t + 10000, t + 2000000);
  ASSERT_TRUE(second);
  EXPECT_NE(p.last_status().reason.find("path blocked"), std::string::npos) << p.last_status().reason;
  CollisionChecker c(p.config().collision);
  c.set_grid(&g);
  for (size_t i = 1; i + 1 < second->waypoints.size(); ++i)
    EXPECT_TRUE(c.edge_free(second->waypoints[i], second->waypoints[i + 1]));
}

// Checks every released path against the map it was planned on: waypoints keep the clearance,
// segments are collision-free (the first, from the vehicle, by the root rule).
struct PathAudit {
  const map::StateGrid* grid = nullptr;
  CollisionChecker checker{CollisionConfig{}};
  int paths = 0;
  int bad = 0;
  size_t max_waypoints = 0;
  double longest_first_step = 0.0;

  void check(const PlannedPath& path) {
    ++paths;
    checker.set_grid(grid);
    max_waypoints = std::max(max_waypoints, path.waypoints.size());
    EXPECT_EQ(path.waypoints.size(), path.yaws.size());
    for (size_t i = 1; i < path.waypoints.size(); ++i) {
      const bool node = checker.node_free(path.waypoints[i]);
      const bool edge = i == 1 ? checker.root_edge_free(path.waypoints[0], path.waypoints[1])
                               : checker.edge_free(path.waypoints[i - 1], path.waypoints[i]);
      if (!node || !edge) ++bad;
      EXPECT_TRUE(node) << "path " << path.plan_id << " waypoint " << i;
      EXPECT_TRUE(edge) << "path " << path.plan_id << " segment " << i;
    }
    if (path.waypoints.size() > 1)
      longest_first_step = std::max(longest_first_step, (path.waypoints[1] - path.waypoints[0]).norm());
  }
};

TEST(Planner, AepFallbackGrowsTowardFarFrontiers) {
  // The corridor's frontier (x = 6.1) is beyond what AEP's local tree (0.5 m box around x = 1)
  // can see with a 2 m sensor: no local gain, nothing cached; the fallback must sample around the
  // frontier and fly there rather than declare the map done.
  map::StateGrid g = corridor();
  PlannerConfig c = test_config("aep");
  c.aep.radius = 0.5;
  c.gain.max_range = 2.0;
  ExplorationPlanner p(c);
  p.set_map(&g);
  p.set_pose(pose({1, 2, 1.2}));
  const auto path = first_path(p, 0, 5000000);
  ASSERT_TRUE(path) << p.last_status().reason;
  EXPECT_GT(path->waypoints.back().x(), 3.5) << p.last_status().reason;
  EXPECT_NE(p.state(), PlannerState::kDone);
}

class Baselines : public ::testing::TestWithParam<const char*> {};

TEST_P(Baselines, ProduceValidPathsAndExploreWithoutCollisions) {
  const SyntheticWorld w = SyntheticWorld::two_rooms();
  ExplorationPlanner p(test_config(GetParam()));
  ExplorationSimOptions o;
  o.max_time = 90;
  ExplorationSim sim(w, p, o);
  PathAudit audit;
  audit.grid = &sim.known();
  const ExplorationSimResult r = sim.run([&](double, const ExplorationPlanner::Output& out) {
    if (out.path) audit.check(*out.path);
  });
  EXPECT_EQ(r.collisions, 0);
  EXPECT_GT(audit.paths, 3);
  EXPECT_EQ(audit.bad, 0);
  EXPECT_GT(r.coverage, 0.6) << GetParam();
  const PlannerKind kind = parse_planner_kind(GetParam());
  if (kind == PlannerKind::kNbv) {
    // Receding horizon: one edge of at most the RRT step.
    EXPECT_LE(audit.max_waypoints, 2u);
    // (plus at most 3 × 0.3 m when the steered point was moved off a wall: CollisionChecker::centre)
    EXPECT_LE(audit.longest_first_step, p.config().nbv.step + 0.9 + 1e-9);
  }
}

INSTANTIATE_TEST_SUITE_P(Planners, Baselines, ::testing::Values("semantic-dep", "dep", "nbv", "aep"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

TEST(Exploration, DepExploresTwoRoomsAndDeclaresDone) {
  const SyntheticWorld w = SyntheticWorld::two_rooms();
  ExplorationPlanner p(test_config());
  ExplorationSimOptions o;
  o.max_time = 200;
  ExplorationSim sim(w, p, o);
  const ExplorationSimResult r = sim.run();
  EXPECT_TRUE(r.done) << r.reason;
  EXPECT_GT(r.coverage, 0.95);
  EXPECT_EQ(r.collisions, 0);
  EXPECT_GT(r.time_85, 0);
  EXPECT_GT(r.charged_s, 0);
}

TEST(Exploration, EmulatedSemanticsFeedsRegionsThatTurnInactive) {
  const SyntheticWorld w = SyntheticWorld::two_rooms();
  ASSERT_EQ(w.objects().size(), 2u);
  ExplorationPlanner p(test_config());
  ExplorationSimOptions o;
  o.max_time = 200;
  o.semantic_weight = 50;
  ExplorationSim sim(w, p, o);
  bool seen_active = false;
  const ExplorationSimResult r = sim.run([&](double, const ExplorationPlanner::Output&) {
    for (const SemanticRegion& s : p.regions()) seen_active |= s.active;
  });
  EXPECT_TRUE(seen_active);
  EXPECT_EQ(r.objects_completed, 2);
  EXPECT_GT(r.objects_time, 0);
  ASSERT_EQ(p.regions().size(), 2u);
  for (const SemanticRegion& s : p.regions()) EXPECT_FALSE(s.active);
  EXPECT_EQ(r.collisions, 0);
}

TEST(Exploration, SameSeedSameFlight) {
  auto fly = [](int64_t seed) {
    const SyntheticWorld w = SyntheticWorld::two_rooms();
    PlannerConfig c = test_config();
    c.seed = seed;
    ExplorationPlanner p(c);
    ExplorationSimOptions o;
    o.max_time = 30;
    ExplorationSim sim(w, p, o);
    return sim.run().released;
  };
  const auto a = fly(5), b = fly(5);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].waypoints, b[i].waypoints);
    EXPECT_EQ(a[i].yaws, b[i].yaws);
  }
}

}  // namespace
}  // namespace semx::planner
