// semantic-room's rules on a small synthetic map (semantic_room_strategy.hpp): where each must
// change DEP's goal, and where it must not.
#include <gtest/gtest.h>

#include "planner_test_util.hpp"
#include "semx/core/angles.hpp"
#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/semantic_room_strategy.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::planner {
namespace {

// SyntheticWorld::two_rooms (x 0-4 and 4.2-8.2, y 0-4, a 1.2 m doorway at y 1.4-2.6 in the wall
// at x 4.0-4.2): the first room is known but for a hidden corner (a pocket of unknown voxels),
// the second only its first 1.5 m. The vehicle stands in the first room; nodes: one by the
// pocket, one in the doorway, one in the second room looking at its unknown part.
struct TwoRoomScene : PlanScene {
  int64_t pocket = -1, doorway = -1, beyond = -1;
  std::vector<int64_t> more;

  TwoRoomScene() : PlanScene("semantic-room") {
    config.gain.min_gain = 300.0;  // the test rays count fewer voxels than the defaults
    const SyntheticWorld w = SyntheticWorld::two_rooms();
    w.reveal(grid, {Eigen::Vector3d(-0.2, -0.2, -0.2), Eigen::Vector3d(5.7, 4.2, 2.7)});
    fill_m(grid, {0.0, 2.9, 0.0}, {1.0, 4.0, 1.3}, map::VoxelState::kUnknown);
    frontiers.reset(grid);
  }
  // A door leaf standing open into the first room beside the doorway's north jamb.
  static SemanticRegion door() {
    SemanticRegion r;
    r.class_id = static_cast<int>(runtime::SemanticClass::kDoor);
    r.centroid = Eigen::Vector3d(3.55, 2.65, 1.0);
    r.weight = 300.0;
    r.radius = 3.0;
    return r;
  }
  Goal choose(DepStrategy& s, const Eigen::Vector3d& door_node = {4.1, 2.0, 1.2},
              const Eigen::Vector3d& beyond_node = {5.2, 2.0, 1.2},
              const std::vector<Eigen::Vector3d>& more_nodes = {}) {
    s.on_map_reset();
    PlanContext ctx = context({2.5, 1.6, 1.2}, -0.5 * core::kPi);
    ctx.min_gain = config.gain.min_gain;
    s.process_map_changes(ctx);
    const int64_t root = s.insert_root(ctx);
    s.graph().node(root).blacklisted_until = 10;  // the choice is between the three nodes
    pocket = s.try_insert(ctx, {1.6, 2.4, 1.0});
    doorway = s.try_insert(ctx, door_node);
    beyond = s.try_insert(ctx, beyond_node);
    for (const Eigen::Vector3d& p : more_nodes) more.push_back(s.try_insert(ctx, p));
    EXPECT_GE(pocket, 0);
    EXPECT_GE(doorway, 0);
    EXPECT_GE(beyond, 0);
    std::string reason;
    if (auto* room = dynamic_cast<SemanticRoomStrategy*>(&s)) return room->select_goal_by_rooms(ctx, &reason);
    return s.select_goal(ctx, s.paper_score(), &reason);
  }
};

TEST(SemanticRoom, ADoorSplitsTheRoadmapIntoRooms) {
  TwoRoomScene s;
  s.regions = {TwoRoomScene::door()};
  SemanticRoomStrategy room(s.config);
  s.choose(room);
  const auto& label = room.room_of();
  EXPECT_EQ(label[static_cast<size_t>(room.root())], 0);  // the vehicle's room
  EXPECT_EQ(label[static_cast<size_t>(s.pocket)], 0);
  EXPECT_EQ(label[static_cast<size_t>(s.doorway)], -1);  // within door_radius of the door
  EXPECT_EQ(label[static_cast<size_t>(s.beyond)], 1);
  // Without the door (and without passage nodes: the doorway is wide enough for a node) the
  // roadmap is one room.
  TwoRoomScene t;
  SemanticRoomStrategy open(t.config);
  t.choose(open);
  EXPECT_EQ(open.room_of()[static_cast<size_t>(t.beyond)], 0);
}

// Finish the room before passing a door: DEP flies on to the second room, whose unknown part
// is worth more per second; semantic-room keeps to the pocket in the vehicle's room first.
TEST(SemanticRoom, ADoorKeepsTheVehicleInItsRoomWhileTheRoomHasGain) {
  TwoRoomScene s;
  s.regions = {TwoRoomScene::door()};
  DepStrategy dep(s.config, true);
  const Goal d = s.choose(dep);
  ASSERT_TRUE(d.valid);
  EXPECT_NE(d.node, s.pocket) << "the scene is meant to make DEP leave the room";
  const double pocket_gain = dep.graph().node(s.pocket).gain.gain;
  ASSERT_GT(pocket_gain, s.config.gain.min_gain);

  s.config.room.finish_gain = 0.5 * pocket_gain;
  SemanticRoomStrategy room(s.config);
  const Goal r = s.choose(room);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.node, s.pocket);
}

TEST(SemanticRoom, WithoutADoorOrWithLittleLeftInTheRoomItFliesDepsGoal) {
  TwoRoomScene base;
  base.regions = {TwoRoomScene::door()};
  DepStrategy dep(base.config, true);
  const Goal d = base.choose(dep);
  const double pocket_gain = dep.graph().node(base.pocket).gain.gain;
  // No door seen: one room, DEP's goal.
  {
    TwoRoomScene s;
    s.config.room.finish_gain = 0.5 * pocket_gain;
    SemanticRoomStrategy room(s.config);
    EXPECT_EQ(s.choose(room).position, d.position);
  }
  // The door seen, but what is left in the room is below finish_gain: DEP's goal.
  {
    TwoRoomScene s;
    s.regions = {TwoRoomScene::door()};
    s.config.room.finish_gain = 2.0 * pocket_gain;
    SemanticRoomStrategy room(s.config);
    EXPECT_EQ(s.choose(room).position, d.position);
  }
}

// Look into a room before entering it (room.return_weight): a node of a room other than the
// vehicle's is scored with its depth past the room's doorway added to its path, the way back
// out; nodes of the vehicle's room and doorway nodes are scored as DEP scores them.
TEST(SemanticRoom, ANodeInAnotherRoomCostsItsDepthPastTheDoorway) {
  TwoRoomScene s;
  s.regions = {TwoRoomScene::door()};
  s.config.room.finish_gain = 0.0;
  s.config.room.return_weight = 2.0;
  SemanticRoomStrategy room(s.config);
  s.choose(room);
  const auto& d = room.last_search().distance;
  const auto i = [](int64_t id) { return static_cast<size_t>(id); };
  ASSERT_EQ(room.room_of()[i(s.beyond)], 1);
  ASSERT_EQ(room.vehicle_room(), 0);
  EXPECT_NEAR(room.scored_distance(s.beyond) - d[i(s.beyond)], 2.0 * (d[i(s.beyond)] - d[i(s.doorway)]),
              1e-9);
  EXPECT_GT(room.scored_distance(s.beyond) - d[i(s.beyond)], 1.0);
  EXPECT_EQ(room.scored_distance(s.doorway), d[i(s.doorway)]);
  EXPECT_EQ(room.scored_distance(s.pocket), d[i(s.pocket)]);
}

TEST(SemanticRoom, TheWayBackOutMakesTheDoorwayTheGoalWhereDepEntersTheRoom) {
  // A doorway node 0.4 m short of the door, where the jambs narrow its view of the second room:
  // DEP flies 1.3 m on into the room, whose view is twice as large.
  const Eigen::Vector3d door_node(3.7, 2.0, 1.2), room_node(5.0, 2.0, 1.2);
  TwoRoomScene base;
  base.regions = {TwoRoomScene::door()};
  DepStrategy dep(base.config, false);
  const Goal d = base.choose(dep, door_node, room_node);
  ASSERT_TRUE(d.valid);
  ASSERT_EQ(d.node, base.beyond) << "the scene is meant to make DEP enter the second room";
  auto room_goal = [&](bool door, double weight) {
    TwoRoomScene s;
    if (door) s.regions = {TwoRoomScene::door()};
    s.config.room.finish_gain = 0.0;
    s.config.room.eq6_reward = false;
    s.config.room.return_weight = weight;
    SemanticRoomStrategy room(s.config);
    const Goal g = s.choose(room, door_node, room_node);
    return g.node == s.doorway ? "doorway" : g.node == s.beyond ? "room" : "other";
  };
  // The rule off, or no door seen (one room): DEP's goal.
  EXPECT_STREQ(room_goal(true, 0.0), "room");
  EXPECT_STREQ(room_goal(false, 5.0), "room");
  // The way back out charged: a look from the doorway first.
  EXPECT_STREQ(room_goal(true, 1.0), "doorway");
}

// Edges are up to 2.5 m long: one through the doorway joins a node 1.1 m before the door's
// centroid to one 1.5 m past it with no node in the doorway, and only room.cut_edges splits them.
TEST(SemanticRoom, AnEdgeThroughADoorwaySplitsTheRoomsOnlyWithCutEdges) {
  for (const bool cut : {false, true}) {
    TwoRoomScene s;
    s.regions = {TwoRoomScene::door()};
    s.config.room.finish_gain = 0.0;
    s.config.room.cut_edges = cut;
    SemanticRoomStrategy room(s.config);
    room.on_map_reset();
    PlanContext ctx = s.context({2.7, 2.0, 1.2}, 0.0);
    ctx.min_gain = s.config.gain.min_gain;
    room.process_map_changes(ctx);
    const int64_t root = room.insert_root(ctx);
    const int64_t past = room.try_insert(ctx, {4.9, 2.0, 1.2});
    ASSERT_GE(past, 0);
    bool joined = false;
    for (const RoadmapEdge& e : room.graph().node(root).edges) joined = joined || e.to == past;
    ASSERT_TRUE(joined) << "the scene is meant to join the two nodes by one edge through the doorway";
    std::string reason;
    room.select_goal_by_rooms(ctx, &reason);
    EXPECT_EQ(room.room_of()[static_cast<size_t>(root)], 0);
    EXPECT_EQ(room.room_of()[static_cast<size_t>(past)], cut ? 1 : 0) << (cut ? "cut" : "not cut");
  }
}

// room.dead_ends_only: a second door next to the second room (a node in its doorway, joined to
// the room's node) makes it a room to fly through, and its depth is not charged.
TEST(SemanticRoom, ARoomWithASecondDoorIsNotChargedTheWayBackWithDeadEndsOnly) {
  SemanticRegion second = TwoRoomScene::door();
  second.centroid = Eigen::Vector3d(5.3, 3.3, 1.0);
  const Eigen::Vector3d second_doorway(5.3, 3.0, 1.2);
  auto charge = [&](bool dead_ends_only, bool second_door) {
    TwoRoomScene s;
    s.regions = {TwoRoomScene::door()};
    if (second_door) s.regions.push_back(second);
    s.config.room.finish_gain = 0.0;
    s.config.room.return_weight = 1.0;
    s.config.room.dead_ends_only = dead_ends_only;
    SemanticRoomStrategy room(s.config);
    s.choose(room, {4.1, 2.0, 1.2}, {5.0, 2.0, 1.2}, {second_doorway});
    EXPECT_GE(s.more.at(0), 0);
    EXPECT_EQ(room.room_of()[static_cast<size_t>(s.beyond)], 1);
    EXPECT_EQ(room.room_of()[static_cast<size_t>(s.more.at(0))], second_door ? -1 : 1);
    bool joined = false;
    for (const RoadmapEdge& e : room.graph().node(s.beyond).edges) joined = joined || e.to == s.more.at(0);
    EXPECT_TRUE(joined) << "the scene is meant to join the room's node to the second doorway";
    return room.scored_distance(s.beyond) - room.last_search().distance[static_cast<size_t>(s.beyond)];
  };
  EXPECT_GT(charge(true, false), 0.5);  // one door: a dead end
  EXPECT_GT(charge(false, true), 0.5);  // two doors, every room charged
  EXPECT_EQ(charge(true, true), 0.0);   // two doors, dead ends only
}

}  // namespace
}  // namespace semx::planner
