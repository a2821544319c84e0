// semantic-fuel: FUEL's frontier-cluster tour (fuel_strategy.hpp) with what the semantic map
// knows and the frontier does not (SemanticFuelConfig):
//  - object pockets (object_pockets): FUEL tours clusters below its size thresholds only after
//    every large one, so the unknown voxels under a table or on top of a cabinet are fetched in
//    the end game, a room at a time. A small cluster at an object that is not fully observed yet
//    (the region's box, grown by object_margin) is toured with the large ones: collected while the
//    vehicle is in its room;
//  - rooms (door_cost, off: it lost): a door region is where one room ends; every tour leg from one
//    room to another costs door_cost seconds more, so the tour changes room as few times as it
//    can. A site's room is the last door its coarse path from the vehicle passes (door_rooms());
//    sites whose path passes no door are in the vehicle's room;
//  - doorway clusters (door_clusters, off: it lost): a small cluster within doorway_radius of a
//    door region is toured with the large ones, as a pocket is: a doorway's frontier is small, the
//    room behind it is not;
//  - DEP until doors (tour_doors, off: measured, not the default): DEP's goals until the semantic
//    map shows that many doors, the tour's after: a tour orders rooms, and with one way onward
//    there is nothing to order;
//  - and doorways first, start turns, DEP first, DEP when far better (SemanticFuelConfig says what
//    each does).
// Everything else is FUEL's, unchanged.
#pragma once

#include <memory>
#include <vector>

#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/fuel_strategy.hpp"

namespace semx::planner {

class SemanticFuelStrategy : public FuelStrategy {
 public:
  explicit SemanticFuelStrategy(const PlannerConfig& config);

  PlanOutcome plan(PlanContext& ctx) override;
  void reset() override;
  void on_map_changes(const std::vector<map::VoxelChange>& changes) override;
  void on_map_reset() override;
  void on_gain_invalidated(const std::vector<map::VoxelKey>& keys) override;
  std::optional<double> goal_score(PlanContext& ctx, const Goal& goal) override;
  void reject_goal(const Goal& goal, int64_t until_cycle) override;
  RoadmapView roadmap(const Goal* goal) const override;

 protected:
  void add_tour_costs(const PlanContext& ctx, const GridSearch& tree,
                      const std::vector<Eigen::Vector3d>& reps, const std::vector<Eigen::Vector3d>& means,
                      TourProblem& problem) const override;
  bool promoted(const PlanContext& ctx, const FrontierClusters::Cluster& cluster) const override;
  double latency_weight(const PlanContext& ctx, const FrontierClusters::Cluster& cluster,
                        double coverage) const override;

 private:
  // greedy_ratio: FUEL's choice, or DEP's when its G / T is that many times the tour goal's.
  PlanOutcome plan_greedy(PlanContext& ctx);
  // A goal's G / T in DEP's measure: the gain in its yaw window (swept from the vehicle's yaw as
  // DEP's scores are, with gain.sweep) over the travel time along its waypoints.
  double dep_rate(PlanContext& ctx, const Goal& goal);

  SemanticFuelConfig rules_;
  double yaw_rate_;
  CostConfig cost_;
  GainEvaluator gains_;  // dep_rate()
  // Whether DEP decides this plan (dep_first_s, tour_doors); latches tour_doors' hand-over.
  bool dep_phase(const PlanContext& ctx);

  // dep_first_s: DEP's roadmap decides until then (it is fed the map all along); greedy_ratio: it
  // decides while its goal is flown.
  std::unique_ptr<DepStrategy> dep_;
  // door_weight: the doors that count in this plan (open_doors()).
  std::vector<SemanticRegion> doors_;
  int64_t first_utime_ = -1;
  bool dep_now_ = false;
  bool doors_handed_over_ = false;  // tour_doors: the tour's for good
  int turns_done_ = 0;
  Goal turn_;  // the turn in place being flown (start_turns)
};

// For each path (vehicle first), the index into `regions` of the last door region it passes
// within `radius` horizontally and `height` vertically, or -1 when it passes none.
std::vector<int> door_rooms(const std::vector<std::vector<Eigen::Vector3d>>& paths,
                            const std::vector<SemanticRegion>& regions, double radius, double height);

// Whether `p` lies within `margin` of the box of an object region (not a door, not structural) that
// is still active (not fully observed) and has an extent.
bool near_unfinished_object(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions,
                            double margin);

// The share of `voxels` (at most `samples` of them, spread over the list) whose centres lie within
// `margin` of the box of an unfinished object (near_unfinished_object); 0 when `voxels` is empty.
double share_near_unfinished_objects(const std::vector<map::VoxelKey>& voxels, const map::KeyMath& keys,
                                     const std::vector<SemanticRegion>& regions, double margin,
                                     size_t samples);

// How many doors `regions` shows: door regions with a centroid, those within `radius`
// (horizontally) of one counted before them one door (a leaf seen from both sides may be two).
int count_doors(const std::vector<SemanticRegion>& regions, double radius);

// Whether `p` lies within `radius` (horizontally) of a door region's centroid.
bool near_door(const Eigen::Vector3d& p, const std::vector<SemanticRegion>& regions, double radius);

// The door regions of `regions` with a room behind them still to see: at least `min_share` of the
// voxels of `grid` within `radius` (horizontally) of the door's centroid, at its height, are
// unknown. min_share 0: every door.
std::vector<SemanticRegion> open_doors(const map::StateGrid& grid, const std::vector<SemanticRegion>& regions,
                                       double radius, double min_share);

// Adds `cost` to the first leg (from the vehicle, node 0) into every site that is not a doorway's
// while any site is (`doorway[i]` is node i + 1's): the tour starts with a doorway.
void add_doorway_first_cost(const std::vector<bool>& doorway, double cost, TourProblem& problem);

// Adds `cost` to every leg of `problem` (node 0 the vehicle, in room -1) between different rooms
// (`room[i]` is node i + 1's).
void add_room_change_cost(const std::vector<int>& room, double cost, TourProblem& problem);

}  // namespace semx::planner
