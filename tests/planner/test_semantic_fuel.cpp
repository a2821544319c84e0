// semantic-fuel's rules (semantic_fuel_strategy.hpp) on a small synthetic map: where each must
// change FUEL's goal, and where it must not.
#include <gtest/gtest.h>

#include "planner_test_util.hpp"
#include "semx/core/angles.hpp"
#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/fuel_strategy.hpp"
#include "semx/planner/semantic_fuel_strategy.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::planner {
namespace {

// A region of class `c` (weight 300, radius 3 m) whose box is `extent` around `centroid`.
SemanticRegion region(runtime::SemanticClass c, const Eigen::Vector3d& centroid,
                      const Eigen::Vector3d& extent, bool active = true) {
  SemanticRegion r;
  r.class_id = static_cast<int>(c);
  r.centroid = centroid;
  r.extent = extent;
  r.weight = 300.0;
  r.radius = 3.0;
  r.active = active;
  return r;
}

// SyntheticWorld::two_rooms (x 0-4 and 4.2-8.2, y 0-4, a doorway at y 1.4-2.6): the first room is
// known but for a small pocket on a cabinet in its corner (a frontier cluster below FUEL's size
// threshold), the second only its first 1.5 m. The vehicle stands in the first room, nearer the
// pocket than the second room's frontier.
struct PocketScene : PlanScene {
  const Eigen::Vector3d pocket{0.25, 3.75, 1.0};

  PocketScene() : PlanScene("semantic-fuel") {
    const SyntheticWorld w = SyntheticWorld::two_rooms();
    w.reveal(grid, {Eigen::Vector3d(-0.2, -0.2, -0.2), Eigen::Vector3d(5.7, 4.2, 2.7)});
    fill_m(grid, {0.0, 3.5, 0.8}, {0.5, 4.0, 1.2}, map::VoxelState::kUnknown);
    frontiers.reset(grid);
  }
  // The cabinet whose top holds the pocket.
  SemanticRegion cabinet(bool active = true) const {
    return region(runtime::SemanticClass::kCabinet, {0.25, 3.75, 0.5}, {0.5, 0.5, 1.0}, active);
  }
  // The first cluster of the plan's tour: its mean.
  Eigen::Vector3d first_site(FuelStrategy& s) {
    PlanContext ctx = context({1.6, 2.4, 1.2}, 0.5 * core::kPi);
    ctx.need_goal = true;
    const PlanOutcome out = s.plan(ctx);
    EXPECT_TRUE(out.goal.valid) << out.reason;
    if (s.tour().empty()) return Eigen::Vector3d::Constant(-1e9);
    return s.clusters().find(s.tour().front())->mean;
  }
  bool at_pocket(const Eigen::Vector3d& p) const { return (p - pocket).norm() < 0.6; }
  // FUEL's first site here: beyond the doorway, the pocket left for later.
  static Eigen::Vector3d fuel_first_site() {
    PocketScene s;
    FuelStrategy fuel(s.config);
    const Eigen::Vector3d f = s.first_site(fuel);
    EXPECT_GT(f.x(), 4.2) << "the scene is meant to make FUEL leave the pocket for later";
    return f;
  }
};

TEST(SemanticFuel, APocketAtAnUnfinishedObjectIsToured) {
  PocketScene::fuel_first_site();
  PocketScene t;
  t.regions = {t.cabinet()};
  SemanticFuelStrategy sem(t.config);
  const Eigen::Vector3d g = t.first_site(sem);
  EXPECT_TRUE(t.at_pocket(g)) << g.transpose();
}

TEST(SemanticFuel, WithoutAnUnfinishedObjectAtThePocketItFliesFuelsTour) {
  const Eigen::Vector3d f = PocketScene::fuel_first_site();
  auto first = [](PocketScene& s) {
    SemanticFuelStrategy sem(s.config);
    return s.first_site(sem);
  };
  {  // no region at all
    PocketScene s;
    EXPECT_EQ(first(s), f);
  }
  {  // the cabinet is fully observed
    PocketScene s;
    s.regions = {s.cabinet(false)};
    EXPECT_EQ(first(s), f);
  }
  {  // an object elsewhere
    PocketScene s;
    SemanticRegion far = s.cabinet();
    far.centroid = Eigen::Vector3d(3.0, 0.5, 0.5);
    s.regions = {far};
    EXPECT_EQ(first(s), f);
  }
  {  // the rule off
    PocketScene s;
    s.regions = {s.cabinet()};
    s.config.semantic_fuel.object_pockets = false;
    EXPECT_EQ(first(s), f);
  }
}

TEST(SemanticFuel, TheObjectWeightPutsThePocketFirstInTheLatencyTour) {
  // The latency tour weighs each site by what it covers: the pocket's few voxels wait for the
  // second room even when pockets are toured with the large clusters.
  auto first = [](bool active, double object_weight) {
    PocketScene s;
    s.config.fuel.latency_tour = true;
    s.config.semantic_fuel.object_weight = object_weight;
    s.regions = {s.cabinet(active)};
    SemanticFuelStrategy sem(s.config);
    return s.first_site(sem);
  };
  PocketScene ref;
  EXPECT_FALSE(ref.at_pocket(first(true, 0.0))) << "the scene is meant to leave the pocket for later";
  EXPECT_TRUE(ref.at_pocket(first(true, 1000.0))) << "an unfinished object's pocket weighs more";
  EXPECT_FALSE(ref.at_pocket(first(false, 1000.0))) << "a fully observed object weighs nothing more";
}

TEST(SemanticFuel, TheShareNearUnfinishedObjectsCountsTheSampledVoxels) {
  const map::KeyMath km(0.1);
  SemanticRegion r;
  r.class_id = static_cast<int>(runtime::SemanticClass::kTable);
  r.centroid = Eigen::Vector3d(1.0, 1.0, 0.4);
  r.extent = Eigen::Vector3d(0.4, 0.4, 0.8);
  const std::vector<SemanticRegion> regions{r};
  std::vector<map::VoxelKey> voxels;
  for (int i = 0; i < 40; ++i) voxels.push_back(km.key(Eigen::Vector3d(0.05 + 0.1 * i, 1.0, 0.4)));
  // The centres x = 0.55 ... 1.45 m lie within 0.3 m of the box (0.8-1.2 m): 10 of the 40 voxels.
  EXPECT_DOUBLE_EQ(share_near_unfinished_objects(voxels, km, regions, 0.3, 64), 0.25);
  // Every 4th voxel (10 tested): x = 0.05, 0.45, ... 3.65; 0.85 and 1.25 are near.
  EXPECT_DOUBLE_EQ(share_near_unfinished_objects(voxels, km, regions, 0.3, 10), 0.2);
  EXPECT_DOUBLE_EQ(share_near_unfinished_objects({}, km, regions, 0.3, 64), 0.0);
  std::vector<SemanticRegion> done = regions;
  done[0].active = false;
  EXPECT_DOUBLE_EQ(share_near_unfinished_objects(voxels, km, done, 0.3, 64), 0.0);
}

// A door region: its centroid (the open leaf's) at `at`.
SemanticRegion door_at(const Eigen::Vector3d& at) {
  return region(runtime::SemanticClass::kDoor, at, {0.05, 0.9, 2.0});
}
TEST(SemanticFuel, ASmallClusterAtADoorIsTouredWithTheLargeOnes) {
  // The pocket stands for a doorway's small frontier: a door region 1 m from it.
  PocketScene s;
  s.regions = {door_at({1.0, 3.6, 1.0})};
  s.config.semantic_fuel.object_pockets = false;
  s.config.semantic_fuel.door_clusters = true;
  SemanticFuelStrategy sem(s.config);
  const Eigen::Vector3d g = s.first_site(sem);
  EXPECT_TRUE(s.at_pocket(g)) << g.transpose();
}

TEST(SemanticFuel, WithoutADoorAtTheSmallClusterItFliesFuelsTour) {
  const Eigen::Vector3d f = PocketScene::fuel_first_site();
  auto first = [](PocketScene& s) {
    s.config.semantic_fuel.object_pockets = false;
    SemanticFuelStrategy sem(s.config);
    return s.first_site(sem);
  };
  {  // the door is the doorway's, 3.9 m from the pocket
    PocketScene s;
    s.config.semantic_fuel.door_clusters = true;
    s.regions = {door_at({4.2, 1.2, 1.0})};
    EXPECT_EQ(first(s), f);
  }
  {  // a door at the pocket, the rule off
    PocketScene s;
    s.regions = {door_at({1.0, 3.6, 1.0})};
    EXPECT_EQ(first(s), f);
  }
}

TEST(SemanticFuel, AnOpenDoorHasThatShareOfItsDiscUnknown) {
  map::StateGrid g(0.1);
  const SemanticRegion door = door_at({2.0, 2.0, 1.0});
  SemanticRegion chair = door;
  chair.class_id = static_cast<int>(runtime::SemanticClass::kChair);
  const std::vector<SemanticRegion> regions{door, chair};
  // Nothing mapped: the door opens on unknown space; a chair is never a door.
  ASSERT_EQ(open_doors(g, regions, 1.0, 0.9).size(), 1u);
  EXPECT_EQ(open_doors(g, regions, 1.0, 0.9)[0].class_id, door.class_id);
  // One side mapped (x < 2 m): about half the disc unknown.
  fill_m(g, {0.0, 0.0, 0.5}, {2.0, 4.0, 1.5}, map::VoxelState::kFree);
  EXPECT_EQ(open_doors(g, regions, 1.0, 0.4).size(), 1u);
  EXPECT_TRUE(open_doors(g, regions, 1.0, 0.6).empty());
  // Only the disc at the door's height counts: space above and below it stays unknown.
  fill_m(g, {2.0, 0.0, 0.9}, {4.0, 4.0, 1.1}, map::VoxelState::kFree);
  EXPECT_TRUE(open_doors(g, regions, 1.0, 0.01).empty());
  // Both sides mapped, but the disc reaches unknown space beyond 2 m: a larger radius sees it.
  EXPECT_EQ(open_doors(g, regions, 3.0, 0.2).size(), 1u);
  EXPECT_EQ(open_doors(g, regions, 1.0, 0.0).size(), 1u) << "min_share 0: every door";
}

TEST(SemanticFuel, TheDoorWeightCountsOnlyDoorsWithSpaceStillToSeeAroundThem) {
  // The pocket stands for a doorway's small frontier (toured with the large clusters as a
  // doorway cluster): the latency tour leaves it for later by its few voxels, and the door's
  // weight puts it first while the door counts.
  const SemanticRegion door = door_at({1.0, 3.6, 1.0});
  auto first = [&](double door_weight, double open_share) {
    PocketScene s;
    s.config.fuel.latency_tour = true;
    s.config.semantic_fuel.object_pockets = false;
    s.config.semantic_fuel.door_clusters = true;
    s.config.semantic_fuel.door_weight = door_weight;
    s.config.semantic_fuel.door_open_share = open_share;
    s.regions = {door};
    SemanticFuelStrategy sem(s.config);
    return s.first_site(sem);
  };
  PocketScene ref;
  // The scene's share of unknown voxels around the door: the pocket and the space behind the walls.
  const std::vector<SemanticRegion> doors{door};
  ASSERT_EQ(open_doors(ref.grid, doors, 2.0, 0.1).size(), 1u);
  ASSERT_TRUE(open_doors(ref.grid, doors, 2.0, 0.5).empty());
  EXPECT_FALSE(ref.at_pocket(first(0.0, 0.0))) << "the scene is meant to leave the pocket for later";
  EXPECT_TRUE(ref.at_pocket(first(1000.0, 0.0))) << "every door counts";
  EXPECT_TRUE(ref.at_pocket(first(1000.0, 0.1))) << "this door has that much unknown around it";
  EXPECT_FALSE(ref.at_pocket(first(1000.0, 0.5))) << "this door has not";
}

TEST(SemanticFuel, ANegativeObjectWeightLeavesTheFrontierAtUnfinishedObjectsForLater) {
  // The pocket stands for a doorway's small frontier (toured with the large clusters as a doorway
  // cluster), and an object's box covers the second room's frontier: the latency tour goes there
  // first by its many voxels, unless what lies at an unfinished object weighs less.
  auto first = [](double object_weight, bool active) {
    PocketScene s;
    s.config.fuel.latency_tour = true;
    s.config.semantic_fuel.object_pockets = false;
    s.config.semantic_fuel.door_clusters = true;
    s.config.semantic_fuel.object_weight = object_weight;
    s.regions = {door_at({1.0, 3.6, 1.0}),
                 region(runtime::SemanticClass::kTable, {5.7, 2.0, 1.35}, {1.0, 4.0, 2.7}, active)};
    SemanticFuelStrategy sem(s.config);
    return s.first_site(sem);
  };
  PocketScene ref;
  EXPECT_FALSE(ref.at_pocket(first(0.0, true))) << "the scene is meant to leave the pocket for later";
  EXPECT_TRUE(ref.at_pocket(first(-1.0, true))) << "the second room's frontier lies at an unfinished object";
  EXPECT_FALSE(ref.at_pocket(first(-1.0, false))) << "a fully observed object changes no weight";
}

TEST(SemanticFuel, NearADoorIsWithinTheRadiusHorizontally) {
  const std::vector<SemanticRegion> doors{door_at({2.0, 0.0, 1.0})};
  EXPECT_TRUE(near_door({3.4, 0.0, 2.4}, doors, 1.5));  // height does not count
  EXPECT_FALSE(near_door({3.6, 0.0, 1.0}, doors, 1.5));
  SemanticRegion chair = door_at({2.0, 0.0, 1.0});
  chair.class_id = static_cast<int>(runtime::SemanticClass::kChair);
  EXPECT_FALSE(near_door({2.0, 0.0, 1.0}, {chair}, 1.5)) << "only doors";
}

TEST(SemanticFuel, StartTurnsLookAroundBeforeTheFirstTour) {
  PocketScene s;
  s.config.semantic_fuel.start_turns = 3;
  SemanticFuelStrategy sem(s.config);
  PlanContext ctx = s.context({1.6, 2.4, 1.2});
  double yaw = 0.0;
  for (int k = 0; k < 3; ++k) {
    ctx.cycle = 2 * k + 1;
    ctx.need_goal = true;
    const Goal g = sem.plan(ctx).goal;
    ASSERT_TRUE(g.valid);
    EXPECT_EQ(g.position, ctx.pose.position) << "a turn in place";
    EXPECT_NEAR(core::yaw_distance(g.yaw, yaw + 2.0 * core::kPi / 3.0), 0.0, 1e-9);
    ctx.cycle = 2 * k + 2;
    ctx.need_goal = false;  // not there yet: the same turn
    EXPECT_EQ(sem.plan(ctx).goal.yaw, g.yaw);
    yaw = g.yaw;
    ctx.pose.yaw = yaw;
  }
  ctx.cycle = 7;
  ctx.need_goal = true;
  const Goal tour = sem.plan(ctx).goal;
  ASSERT_TRUE(tour.valid);
  EXPECT_GT((tour.position - ctx.pose.position).norm(), 0.3) << "then FUEL's tour";
}

TEST(SemanticFuel, DepFirstFliesDepsGoalUntilItsTimeThenFuelsTour) {
  auto goal = [](Strategy& s, PocketScene& scene, int64_t utime) {
    PlanContext ctx = scene.context({1.6, 2.4, 1.2});
    ctx.pose.utime = utime;
    ctx.min_gain = scene.config.gain.min_gain;
    ctx.need_goal = true;
    return s.plan(ctx).goal;
  };
  PocketScene a, b, c, d;
  DepStrategy dep(a.config, false);
  a.config.semantic_fuel.dep_first_s = 10.0;
  b.config.semantic_fuel.dep_first_s = 10.0;
  SemanticFuelStrategy first(b.config);
  const Goal g = goal(dep, a, 0);
  ASSERT_TRUE(g.valid);
  EXPECT_EQ(goal(first, b, 0).position, g.position) << "DEP's goal before dep_first_s";
  FuelStrategy fuel(c.config);
  const Goal f = goal(fuel, c, 0);
  ASSERT_GT((f.position - g.position).norm(), 0.1) << "the scene is meant to tell DEP's goal from FUEL's";
  d.config.semantic_fuel.dep_first_s = 10.0;
  SemanticFuelStrategy later(d.config);
  goal(later, d, 0);
  d.rng = core::SplitMixRng(1);
  EXPECT_EQ(goal(later, d, 11000000).position, f.position) << "FUEL's tour after";
}

TEST(SemanticFuel, DoorsAreCountedOncePerDoorRadius) {
  EXPECT_EQ(count_doors({}, 1.0), 0);
  PocketScene s;
  SemanticRegion cabinet = s.cabinet();
  SemanticRegion unplaced = door_at({1.0, 1.0, 1.0});
  unplaced.centroid = Eigen::Vector3d::Constant(std::nan(""));
  EXPECT_EQ(count_doors({cabinet, unplaced}, 1.0), 0) << "only door regions with a centroid";
  EXPECT_EQ(count_doors({door_at({4.2, 2.0, 1.0}), door_at({4.2, 2.7, 1.0})}, 1.0), 1)
      << "one leaf seen twice";
  EXPECT_EQ(count_doors({door_at({4.2, 2.0, 1.0}), door_at({4.2, 3.2, 1.0})}, 1.0), 2);
  EXPECT_EQ(count_doors({door_at({4.2, 2.0, 1.0}), door_at({4.2, 2.0, 2.5})}, 1.0), 1) << "horizontally";
}

// DEP's goal while the map shows fewer doors than tour_doors, FUEL's tour once it shows that many,
// and for good: a door that drops out of the regions does not hand the plan back to DEP.
TEST(SemanticFuel, TourDoorsFliesDepsGoalUntilThatManyDoorsAreSeenThenFuelsTourForGood) {
  auto goal = [](Strategy& s, PocketScene& scene) {
    PlanContext ctx = scene.context({1.6, 2.4, 1.2});
    ctx.min_gain = scene.config.gain.min_gain;
    ctx.need_goal = true;
    return s.plan(ctx).goal;
  };
  const std::vector<SemanticRegion> one = {door_at({4.2, 2.0, 1.0}), door_at({4.2, 2.6, 1.0})};
  const std::vector<SemanticRegion> two = {door_at({4.2, 2.0, 1.0}), door_at({8.0, 3.9, 1.0})};
  PocketScene a, c;
  DepStrategy dep(a.config, false);
  const Goal g = goal(dep, a);
  FuelStrategy fuel(c.config);
  const Goal f = goal(fuel, c);
  ASSERT_TRUE(g.valid && f.valid);
  ASSERT_GT((f.position - g.position).norm(), 0.1) << "the scene is meant to tell DEP's goal from FUEL's";
  {
    PocketScene s;
    s.config.semantic_fuel.tour_doors = 2;
    s.regions = one;
    SemanticFuelStrategy sem(s.config);
    EXPECT_EQ(goal(sem, s).position, g.position) << "one door (seen as two regions): DEP's goal";
  }
  PocketScene s;
  s.config.semantic_fuel.tour_doors = 2;
  s.regions = two;
  SemanticFuelStrategy sem(s.config);
  EXPECT_EQ(goal(sem, s).position, f.position) << "two doors: FUEL's tour";
  s.regions.clear();
  s.rng = core::SplitMixRng(1);
  EXPECT_EQ(goal(sem, s).position, f.position) << "the hand-over holds";
  sem.reset();
  s.rng = core::SplitMixRng(1);
  EXPECT_EQ(goal(sem, s).position, g.position) << "until a new run";
}

// The tour's first goal is the pocket on the cabinet (a few voxels); DEP's is toward the second
// room, whose unknown space its gain counts. With greedy_ratio DEP's goal is flown when its G / T
// is that many times the pocket's, and the pocket when no ratio that high is met.
TEST(SemanticFuel, GreedyRatioFliesDepsGoalWhenItsRateIsThatManyTimesTheToursGoal) {
  auto goal = [](double ratio) {
    PocketScene s;
    s.regions = {s.cabinet()};
    s.config.semantic_fuel.greedy_ratio = ratio;
    SemanticFuelStrategy sem(s.config);
    PlanContext ctx = s.context({1.6, 2.4, 1.2}, 0.5 * core::kPi);
    ctx.min_gain = s.config.gain.min_gain;
    ctx.need_goal = true;
    return sem.plan(ctx).goal;
  };
  PocketScene a;
  a.regions = {a.cabinet()};
  DepStrategy dep(a.config, false);
  PlanContext actx = a.context({1.6, 2.4, 1.2}, 0.5 * core::kPi);
  actx.min_gain = a.config.gain.min_gain;
  actx.need_goal = true;
  const Goal d = dep.plan(actx).goal;
  ASSERT_TRUE(d.valid);
  ASSERT_FALSE(a.at_pocket(d.position)) << "the scene is meant to tell DEP's goal from the tour's";

  const Goal tour = goal(1e6);
  ASSERT_TRUE(tour.valid);
  EXPECT_LT((tour.position - a.pocket).norm(), a.config.fuel.view_radius_max + 0.1)
      << "no ratio met: the tour's goal, the pocket's view " << tour.position.transpose();
  const Goal greedy = goal(2.0);
  ASSERT_TRUE(greedy.valid);
  EXPECT_LT((greedy.position - d.position).norm(), 1e-9) << "DEP's goal: " << greedy.position.transpose();
  EXPECT_DOUBLE_EQ(greedy.score, d.score);
}

TEST(SemanticFuel, NearAnUnfinishedObjectIsWithinItsBoxAndMargin) {
  SemanticRegion r;
  r.class_id = static_cast<int>(runtime::SemanticClass::kTable);
  r.centroid = Eigen::Vector3d(2.0, 2.0, 0.4);
  r.extent = Eigen::Vector3d(1.2, 0.8, 0.8);
  const std::vector<SemanticRegion> regions{r};
  EXPECT_TRUE(near_unfinished_object({2.0, 2.0, 0.2}, regions, 0.5));   // under it
  EXPECT_TRUE(near_unfinished_object({3.0, 2.0, 0.9}, regions, 0.5));   // by its edge
  EXPECT_FALSE(near_unfinished_object({3.2, 2.0, 0.4}, regions, 0.5));  // beyond the margin
  std::vector<SemanticRegion> other = regions;
  other[0].extent = Eigen::Vector3d::Zero();  // no extent known
  EXPECT_FALSE(near_unfinished_object({2.0, 2.0, 0.2}, other, 0.5));
  other = regions;
  other[0].class_id = static_cast<int>(runtime::SemanticClass::kDoor);
  EXPECT_FALSE(near_unfinished_object({2.0, 2.0, 0.2}, other, 0.5));
  other[0].class_id = static_cast<int>(runtime::SemanticClass::kWall);
  EXPECT_FALSE(near_unfinished_object({2.0, 2.0, 0.2}, other, 0.5));
}

TEST(SemanticFuel, ALegBetweenRoomsCostsTheDoorCost) {
  // Paths from the vehicle: the first passes no door, the second the door at x = 4, the third the
  // door at x = 4 and then the one at x = 8 (its room is the last door's).
  SemanticRegion d1, d2;
  d1.class_id = d2.class_id = static_cast<int>(runtime::SemanticClass::kDoor);
  d1.centroid = Eigen::Vector3d(4.0, 2.0, 1.0);
  d2.centroid = Eigen::Vector3d(8.0, 2.0, 1.0);
  const std::vector<std::vector<Eigen::Vector3d>> paths = {
      {{1, 2, 1}, {2, 2, 1}},
      {{1, 2, 1}, {4.2, 2, 1}, {6, 2, 1}},
      {{1, 2, 1}, {4.2, 2, 1}, {7.8, 2.3, 1}, {10, 2, 1}}};
  const std::vector<int> room = door_rooms(paths, {d1, d2}, 1.0, 1.5);
  EXPECT_EQ(room, (std::vector<int>{-1, 0, 1}));
  TourProblem p;
  p.n = 4;
  p.cost.assign(16, 1.0);
  add_room_change_cost(room, 10.0, p);
  EXPECT_EQ(p.cost[0 * 4 + 1], 1.0);   // vehicle to its own room
  EXPECT_EQ(p.cost[0 * 4 + 2], 11.0);  // vehicle to the room behind the first door
  EXPECT_EQ(p.cost[2 * 4 + 3], 11.0);
  EXPECT_EQ(p.cost[3 * 4 + 1], 11.0);
  EXPECT_EQ(p.cost[1 * 4 + 0], 1.0);  // returns are free and stay so
}

TEST(SemanticFuel, ADoorwayFirstCostsTheFirstLegIntoOtherSitesOnlyWhileADoorwayIsLeft) {
  TourProblem p;
  p.n = 3;
  p.cost.assign(9, 1.0);
  add_doorway_first_cost({true, false}, 20.0, p);
  EXPECT_EQ(p.cost[1], 1.0);   // into the doorway
  EXPECT_EQ(p.cost[2], 21.0);  // into the other site first
  EXPECT_EQ(p.cost[1 * 3 + 2], 1.0) << "legs after the first are FUEL's";
  TourProblem q;
  q.n = 3;
  q.cost.assign(9, 1.0);
  add_doorway_first_cost({false, false}, 20.0, q);
  EXPECT_EQ(q.cost, std::vector<double>(9, 1.0)) << "no doorway: FUEL's tour";
}

}  // namespace
}  // namespace semx::planner
