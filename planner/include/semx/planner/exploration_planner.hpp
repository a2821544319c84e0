// The planner's main loop (paper Fig. 2, "Main Loop"): runs a planning method (strategy.hpp) on
// message time, decides when to replan, charges planning time, and says when exploration is done.
//
//   ExplorationPlanner p(config);
//   p.set_map(&mirror.grid());                  // and after every delta: p.on_map_changes(changes)
//   p.set_pose(pose);  p.set_regions(regions);  p.on_controller_status(state, plan_id);
//   auto out = p.tick(utime);                   // on every clock tick
//   if (out.path) publish PLAN_PATH; if (out.roadmap) ROADMAP; if (out.status) PLANNER_STATUS
//
// A cycle runs at most every 1/rate_hz of message time, and not before the previous cycle's
// charged time has passed. It replans (needs a new goal) when there is no goal, the goal was
// reached (within goal_tolerance and yaw_tolerance, or the controller HOLDs the path's end near
// it, for dwell_s; what the gain still counts in the camera's window there is then marked
// unobservable and no gain counts it again), the rest of the path is no longer collision-free, or the
// controller reported BRAKING, STALE_INPUT or REJECTED for the current plan (REJECTED also blacklists the
// goal for blacklist_cycles; a reached goal is skipped for visited_cycles). DEP updates its roadmap every
// cycle and, while flying, switches to a new goal when its score exceeds hysteresis × the current goal's
// score now, or when the current goal's gain fell below min_gain; NBV and AEP plan only when a new goal is
// needed (receding horizon). A cycle that needs a goal and finds none is RECOVERING (the next cycles sample
// around frontier clusters only, with twice the attempts); after done_cycles such cycles in a row
// the planner is DONE, for good, with the strategy's reason. When the path ahead became blocked
// and no other goal is found, a one-waypoint path at the vehicle (hold there) is sent.
//
// Outputs of a cycle run at message time t (path, roadmap, status) are released by the first
// tick at or after t + charged_s (charge_model.hpp); a path whose first waypoint the vehicle has
// left by more than loop.max_start_offset by then is dropped and replanned at once.
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/frontier_tracker.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/plan_types.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/planner/semantic_reward.hpp"
#include "semx/planner/strategy.hpp"
#include "semx/planner/voxel_set.hpp"

namespace semx::planner {

class ExplorationPlanner {
 public:
  explicit ExplorationPlanner(const PlannerConfig& config);

  const PlannerConfig& config() const { return config_; }
  PlannerKind kind() const { return kind_; }

  // The map to plan on; must stay valid until replaced. A different grid counts as a reset.
  void set_map(const map::StateGrid* grid);
  // After the grid applied a delta (`changes` are its voxels and new states).
  void on_map_changes(const std::vector<map::VoxelChange>& changes);
  // After the grid's content was replaced (a snapshot).
  void on_map_reset();
  void set_pose(const VehiclePose& pose);
  void set_regions(std::vector<SemanticRegion> regions) { regions_ = std::move(regions); }
  // The world's ground truth, for the known-map oracle only (Strategy::set_truth; the other
  // planners ignore it). Must outlive the planner's use.
  void set_truth(const TruthMap* truth) { strategy_->set_truth(truth); }
  // `utime`: the status's message time (-1: unknown). A controller that reports no plan at all
  // (IDLE or STALE_INPUT, plan 0) loop.lost_path_s after a path went out has lost it (it was
  // restarted): the planner plans again from where the vehicle is.
  void on_controller_status(ControllerState state, int64_t plan_id, int64_t utime = -1);

  struct Output {
    std::optional<PlannedPath> path;
    std::optional<StatusReport> status;
    std::optional<RoadmapView> roadmap;
  };
  Output tick(int64_t utime);
  // tick() in two steps, for a node that acks the tick before the cycle's work: poll() does all
  // tick() does but run a due cycle, and says whether one is due; run_due_cycle() then runs it.
  // Its outputs wait for a later tick when min_charge_us() is at least a tick.
  Output poll(int64_t utime, bool& cycle_due);
  void run_due_cycle(int64_t utime);
  // The least a cycle is charged (charge.scale · charge.min_s), in µs.
  int64_t min_charge_us() const;
  // The earliest message time at which tick() can output anything, whatever arrives before it
  // (the next cycle or release; `utime` when that depends on what arrives).
  int64_t quiet_until(int64_t utime) const;
  // A new episode: forget the roadmap, goal and state (the map is the caller's).
  void reset();

  PlannerState state() const { return state_; }
  int64_t iteration() const { return iteration_; }
  int64_t plan_id() const { return plan_id_; }
  const Goal& goal() const { return goal_; }
  bool busy() const { return pending_.active; }
  const StatusReport& last_status() const { return last_status_; }
  const FrontierTracker& frontiers() const { return frontiers_; }
  const VoxelSet& unobservable() const { return unobservable_; }
  // Voxels no gain should count from now on (known to be unobservable by other means).
  void add_unobservable(const std::vector<map::VoxelKey>& keys);
  Strategy& strategy() { return *strategy_; }
  const std::vector<SemanticRegion>& regions() const { return regions_; }

 private:
  struct Pending {
    bool active = false;
    int64_t ready_utime = 0;
    bool has_path = false;
    Goal goal;
    std::optional<StatusReport> status;
    std::optional<RoadmapView> roadmap;
  };
  void run_cycle(int64_t utime);
  void release(Output& out, int64_t utime);
  // Whether the vehicle is within tolerance of the goal, and since when (arrived_utime_).
  void track_arrival(int64_t utime);
  // When the goal counts as reached: dwell_s after the arrival, or after utime if not arrived.
  int64_t reached_utime(int64_t utime) const;
  bool goal_reached(int64_t utime);
  // The controller has held the path's end for short_hold_s with the vehicle away from the goal.
  bool held_short(int64_t utime);
  // After a goal was reached: what the gain still counts in the camera's window from the pose is
  // unobservable from here (inside solids, in the camera's blind spots); gains stop counting it.
  void mark_unobservable(CycleCounters& c);
  bool path_blocked() const;
  StatusReport make_status(PlannerState state, const std::string& reason, const CycleCounters& c,
                           double charged, const Goal& best, const RoadmapView* view) const;

  PlannerConfig config_;
  PlannerKind kind_;
  std::unique_ptr<Strategy> strategy_;
  CollisionChecker checker_;
  FrontierTracker frontiers_;
  GainEvaluator gains_;
  VoxelSet unobservable_;
  int64_t arrived_utime_ = -1;  // since when the vehicle is within tolerance of the goal
  int64_t short_since_ = -1;    // since when the controller holds away from the goal
  int64_t released_utime_ = -1;  // when the goal's path went out
  core::SplitMixRng rng_;
  const map::StateGrid* grid_ = nullptr;
  std::optional<VehiclePose> pose_;
  std::vector<SemanticRegion> regions_;

  PlannerState state_ = PlannerState::kInit;
  std::string reason_;
  int64_t iteration_ = 0;
  int64_t plan_id_ = 0;
  int64_t next_cycle_utime_ = -1;
  int no_goal_cycles_ = 0;
  Goal goal_;  // being flown (valid after its path was released)
  bool controller_trigger_ = false;
  bool controller_rejected_ = false;
  bool controller_holding_ = false;
  std::string controller_reason_;
  bool init_reported_ = false;
  Pending pending_;
  StatusReport last_status_;
  // What the goals flown lately delivered (loop.yield_goals): per goal, the gain it was chosen
  // with and the voxels the map gained while it was flown.
  struct Yield {
    double promised = 0;
    int64_t delivered = 0;
  };
  std::deque<Yield> yields_;
  double open_promise_ = 0;
  int64_t open_known_ = -1;  // known voxels when the goal being flown was released; -1: none
  void open_yield(double gain);
  void close_yield();
  double min_gain_now() const;
};

}  // namespace semx::planner
