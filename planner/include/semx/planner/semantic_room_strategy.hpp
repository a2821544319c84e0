// semantic-room: DEP's roadmap and score (dep_strategy.hpp) with goals ordered by the rooms the
// semantic map shows (issue 30; docs/planner.md, "semantic-room").
//
// What semantics knows here and the gain does not: a door region means a doorway, and a doorway
// is where one room ends and the next begins. Each cycle the reachable roadmap is split into
// rooms at its doorways: the nodes within room.door_radius (horizontally) of a door region's
// centroid (semantic), and with room.passages_bound the passage nodes DEP centres in gaps too
// narrow for a node (geometric: a narrow passage, with or without a door seen). A room is a
// connected part of what is left; the vehicle's room is the root's.
//
// Ordering rules (DepStrategy::select_goal's tiers; a node of a higher tier outranks every node
// of a lower one, and within a tier DEP's score decides):
//   - finish the room before passing a door: while a node of the vehicle's room has a gain of
//     room.finish_gain, those nodes outrank every other;
//   - with room.tour, a global order of rooms: among the rooms with a node of finish_gain, the
//     first of the shortest open tour through them from the vehicle (roadmap distances between
//     each room's best node) is the one whose nodes of finish_gain outrank the rest;
//   - with room.return_weight, look into a room before entering it: a node of another room is
//     scored as if the way back out to its doorway were flown too.
// Below finish_gain everywhere, DEP's ranking decides among all nodes as before. Without door
// regions and passage nodes the whole roadmap is one room.
#pragma once

#include <string>
#include <vector>

#include "semx/planner/dep_strategy.hpp"

namespace semx::planner {

class SemanticRoomStrategy : public DepStrategy {
 public:
  explicit SemanticRoomStrategy(const PlannerConfig& config);

  PlanOutcome plan(PlanContext& ctx) override;
  // Steps 4-6 of DEP's cycle (select_goal) with the room tiers, on the roadmap as it is.
  Goal select_goal_by_rooms(PlanContext& ctx, std::string* reason);

  // Per slot of the last cycle: the room of each reachable node (0 the vehicle's, when the
  // vehicle is in one), -1 for doorway nodes and nodes the root does not reach.
  const std::vector<int>& room_of() const { return room_; }
  // The vehicle's room in the last cycle (0), or -1 when it stands in a doorway.
  int vehicle_room() const { return vehicle_room_; }
  // The room whose nodes of finish_gain outrank the others in the last cycle, -1 for none.
  int target_room() const { return target_; }
  // Node `id` stands in a doorway this cycle (a boundary between rooms).
  bool doorway(const PlanContext& ctx, int64_t id) const;
  // The index in ctx.regions of a door region within door_radius (horizontally) of p, -1 for none.
  int door_near(const PlanContext& ctx, const Eigen::Vector3d& p) const;
  // With room.cut_edges: the door region (index) the edge a-b passes within door_radius of, -1 for
  // none (and always without cut_edges).
  int door_crossed(const PlanContext& ctx, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

 private:
  // Labels the reachable roadmap's rooms and picks the target room (after the cycle's search).
  void label_rooms(PlanContext& ctx);
  void choose_target(PlanContext& ctx, int rooms);
  // The tier of node `id` (labels the rooms on its first call of a cycle: after the search).
  TierFn tiers(PlanContext& ctx, bool* labelled);
  // The gain finish_gain is compared with (RoomConfig::boundary_gain).
  double room_gain(const RoadmapNode& n) const;

  // room.return_weight: every node of a room not the vehicle's costs its depth past the room's
  // doorway (extra_distance_); labels the rooms first.
  void searched(PlanContext& ctx) override;

  RoomConfig rules_;
  std::vector<int> room_;  // per slot
  int target_ = -1;
  int vehicle_room_ = -1;
  bool labelled_in_search_ = false;  // searched() labelled the rooms for this cycle's search
};

}  // namespace semx::planner
