// What the main loop (ExplorationPlanner) asks of a planning method: one cycle's best goal and
// the path to it. DEP (with or without semantics), NBV, AEP and FUEL implement it (dep_strategy.hpp,
// nbv_strategy.hpp, aep_strategy.hpp, fuel_strategy.hpp) on the same map, sensor model and
// collision checks; the known-map oracle (oracle_strategy.hpp) too, on the world's ground truth
// instead.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "semx/core/angles.hpp"
#include "semx/core/random.hpp"
#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/frontier_tracker.hpp"
#include "semx/planner/plan_types.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/planner/semantic_reward.hpp"
#include "semx/planner/truth_map.hpp"
#include "semx/planner/voxel_set.hpp"

namespace semx::planner {

struct Goal;

struct PlanContext {
  const map::StateGrid* grid = nullptr;
  VehiclePose pose;
  const std::vector<SemanticRegion>* regions = nullptr;  // empty when semantics are off
  const FrontierTracker* frontiers = nullptr;
  // Voxels that gains ignore (seen as unobservable after a visit; exploration_planner.hpp).
  const VoxelSet* unobservable = nullptr;
  int64_t cycle = 0;
  bool recovering = false;  // the previous cycles found no goal: sample for frontiers
  // The gain a goal must have: gain.min_gain, raised by the main loop when recent goals delivered
  // less than their gain promised (loop.yield_goals).
  double min_gain = 0.0;
  // The main loop will fly this cycle's goal whatever it is (no goal yet, the goal was reached,
  // the path is blocked, the controller gave up on it); otherwise it keeps the current goal unless
  // goal_score() says otherwise. FUEL decides on it whether to replan its tour.
  bool need_goal = false;
  // When a goal is flown (need_goal false): that goal, and how many times its goal_score() another
  // goal must score for the main loop to switch (loop.hysteresis; infinite for a held goal). A
  // ranking may stop once nothing left in it can score that much: its answer would change nothing.
  const Goal* flown = nullptr;
  double switch_factor = 0.0;
  core::SplitMixRng* rng = nullptr;
  CycleCounters* counters = nullptr;
};

// A goal and the path to it.
struct Goal {
  bool valid = false;
  int64_t node = -1;  // roadmap node id (DEP, AEP fallback), -1 otherwise
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  double gain = 0.0, reward = 0.0, cost = 0.0, score = 0.0;
  std::vector<Eigen::Vector3d> waypoints;  // first = the vehicle's position
  std::vector<double> yaws;
  // A stop chosen after the score (DEP's pockets before a far goal, loop.pocket_detour): the main
  // loop flies it until it is reached or no longer informative, without switching on score (every
  // pocket scores below the far goal it was put before).
  bool held = false;
  // A look across a cut of the roadmap (DEP's recovery, loop.cut_looks): flown to re-observe the
  // passage between the vehicle's part of the roadmap and informative nodes it cannot reach; it
  // promises no gain, and any goal that scores at all replaces it.
  bool look = false;
};

// A turn in place at `at` by `turn` rad from `from_yaw`: its cost the turn's time at `yaw_rate`,
// a nominal gain of 1 (it looks around; what it will see is not modelled).
inline Goal turn_in_place(const Eigen::Vector3d& at, double from_yaw, double turn, double yaw_rate) {
  Goal g;
  g.valid = true;
  g.position = at;
  g.yaw = core::wrap_angle(from_yaw + turn);
  g.gain = 1.0;
  g.cost = std::abs(turn) / yaw_rate;
  g.score = g.gain / g.cost;
  g.waypoints = {at};
  g.yaws = {g.yaw};
  return g;
}

struct PlanOutcome {
  Goal goal;           // invalid when nothing worth flying to was found
  std::string reason;  // why there is no goal (becomes the DONE reason)
  // No goal, but roadmap nodes with gain exist that the vehicle cannot reach (the graph came
  // apart, e.g. edges through a doorway were pruned): worth recovering longer before DONE.
  int64_t unreachable_informative = 0;
  // No goal only because every informative goal left is skipped for now (one the controller
  // rejected, one just reached: Strategy::reject_goal): the last cycle of those skips, -1 when
  // none. The main loop does not declare DONE before it has planned once after it: a skip is a
  // pause, not a verdict (FUEL in env3 with sensor noise ended DONE at 65 % when its skips and
  // the recovery cycles ran out in the same cycle).
  int64_t skipped_until = -1;
  // Nothing is left to do at all (the oracle flew its last viewpoint): DONE at once, without the
  // done_cycles of cycles that look for a goal again.
  bool finished = false;
  // The goal is the first stop of a tour (DEP's end game): the main loop keeps the goal being
  // flown until it is reached or no longer informative, without switching on score. The tour's
  // stops, 0 when the goal is no tour's.
  int tour_stops = 0;
  // The goal is the first of this many pockets put before the score's far goal (loop.pocket_detour;
  // goal.held is set); 0 otherwise.
  int pocket_stops = 0;
};

class Strategy {
 public:
  virtual ~Strategy() = default;

  // The map changed (the grid already holds the new states) / was replaced wholesale.
  virtual void on_map_changes(const std::vector<map::VoxelChange>& changes) = 0;
  virtual void on_map_reset() = 0;
  // The gain model changed for these voxels (they became unobservable): cached gains in sensor
  // range of them are stale.
  virtual void on_gain_invalidated(const std::vector<map::VoxelKey>& keys) = 0;
  // One planning cycle.
  virtual PlanOutcome plan(PlanContext& ctx) = 0;
  // The score the goal being flown has now (same cycle's roadmap), or nullopt when it is gone or
  // no longer worth it. Receding-horizon methods return nullopt without work (never called).
  virtual std::optional<double> goal_score(PlanContext& ctx, const Goal& goal) = 0;
  // The controller could not fly to this goal: avoid it for a while.
  virtual void reject_goal(const Goal& goal, int64_t until_cycle) = 0;
  // NBV and AEP fly the first edge of their best branch and replan on arrival; DEP keeps its
  // goal and switches only for a much better one.
  virtual bool receding_horizon() const = 0;
  virtual RoadmapView roadmap(const Goal* goal) const = 0;
  virtual void reset() = 0;
  // The world's ground truth (must outlive the strategy's use). Only the known-map oracle reads
  // it; every exploration method ignores it, so none can cheat by accident.
  virtual void set_truth(const TruthMap* /*truth*/) {}
  // The strategy's paths are safe by its own knowledge, not the live map's: the main loop does not
  // call them blocked when they cross space the live map does not know yet (the oracle's legs do).
  virtual bool trusts_own_paths() const { return false; }
};

// The strategy for `config.kind()`.
std::unique_ptr<Strategy> make_strategy(const PlannerConfig& config);

// Yaws for a polyline: from `start_yaw` to `goal_yaw` (the shorter way), linear in arc length.
std::vector<double> interpolate_yaws(const std::vector<Eigen::Vector3d>& waypoints, double start_yaw,
                                     double goal_yaw);

}  // namespace semx::planner
