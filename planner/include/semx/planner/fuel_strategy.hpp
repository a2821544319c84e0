// FUEL: fast UAV exploration with an incremental frontier structure and hierarchical planning
// (Zhou et al., RA-L 2021), a baseline on the same map, sensor model, collision checks, vehicle
// limits and main loop as DEP, NBV and AEP.
//
// Each cycle:
//  1. the frontier clusters are updated around the map's changes (FrontierClusters: connected
//     frontier voxels, split along their principal axis while too large), and every new cluster
//     gets its viewpoints (ViewpointSampler: candidates on circles around it, collision-free with
//     the clearance of DEP's goals, each with the yaw that sees most of the cluster, sorted by how
//     much they see);
//  2. the tour is planned again when the main loop needs a goal (none yet, reached, path blocked,
//     the controller gave up), when the target cluster is covered (covered_fraction of its voxels
//     no longer frontier) or its viewpoint no longer free, and every replan_period s; otherwise
//     the current goal stays (FUEL's FSM). A periodic replan switches target only when its tour
//     is switch_margin cheaper than the best tour that keeps the current target first;
//  3. planning: a Dijkstra over the coarse lattice from the vehicle (GridSearch) gives the travel
//     distance to every viewpoint; each cluster is represented by its best-covering reachable
//     viewpoint not within min_view_distance of the vehicle; the distances between clusters come
//     from a Dijkstra from each representative, kept until either cluster changes (FUEL's
//     incremental cost matrix; cost_budget settled cells per cycle, estimates for the rest);
//  4. the global tour: an asymmetric TSP from the vehicle over the representatives, cost = travel
//     time (travel_time(): the longer of path length / cost.velocity and yaw change /
//     cost.yaw_rate, FUEL's own t_lb), returns free (TourSolver);
//  5. local refinement: the first clusters of the tour, each choosing among its top viewpoints,
//     by a shortest path through the layers (FUEL's refineLocalTour); the first choice is the goal;
//  6. the path: A* over voxels around the coarse path, shortened to segments that pass the
//     collision check (GridSearch::find_path); yaws turn toward the goal's as fast as cost.yaw_rate
//     allows along it. A goal without a path is skipped for loop.blacklist_cycles.
// No cluster with a reachable viewpoint: no goal, with the reason, and the main loop declares DONE;
// except before the first tour goal, when the vehicle first turns in place, a quarter turn at a
// time (at most four), held to its end: the first camera view can leave the frontier clusters
// without a free viewpoint (a start facing a wall: a 62 m² generated world ended DONE at 1.2 s
// with 3.6 % of T), or show nothing at all (a wall nearer than the camera's least depth), and
// what is around the start gives them one.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "semx/planner/cluster_viewpoints.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/frontier_clusters.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/grid_search.hpp"
#include "semx/planner/strategy.hpp"
#include "semx/planner/tour_solver.hpp"

namespace semx::planner {

class FuelStrategy : public Strategy {
 public:
  explicit FuelStrategy(const PlannerConfig& config);

  void on_map_changes(const std::vector<map::VoxelChange>& changes) override;
  void on_map_reset() override;
  void on_gain_invalidated(const std::vector<map::VoxelKey>& keys) override;
  PlanOutcome plan(PlanContext& ctx) override;
  std::optional<double> goal_score(PlanContext& ctx, const Goal& goal) override;
  void reject_goal(const Goal& goal, int64_t until_cycle) override;
  bool receding_horizon() const override { return false; }
  RoadmapView roadmap(const Goal* goal) const override;
  void reset() override;

  const FrontierClusters& clusters() const { return clusters_; }
  // The viewpoints of a cluster (empty when it has none or does not exist).
  const std::vector<Viewpoint>& viewpoints(int64_t cluster) const;
  // The last planned tour's clusters, in visiting order.
  const std::vector<int64_t>& tour() const { return tour_; }
  // Why the last plan() planned again ("" when it kept the goal).
  const std::string& replan_reason() const { return replan_reason_; }
  // Whether the last plan() chose a new goal, which supersedes the one flown (goal_score()).
  bool switched() const { return switch_; }

 protected:
  // A hook for planners built on FUEL's tour (semantic_fuel_strategy.hpp): extra costs (s) added to
  // the global tour's problem before it is solved. Node 0 is the vehicle, node i + 1 the site of
  // the i-th representative viewpoint `reps[i]`, whose cluster's mean is `means[i]`; `tree` holds
  // the coarse search from the vehicle (tree_path()). FUEL adds nothing.
  virtual void add_tour_costs(const PlanContext& /*ctx*/, const GridSearch& /*tree*/,
                              const std::vector<Eigen::Vector3d>& /*reps*/,
                              const std::vector<Eigen::Vector3d>& /*means*/, TourProblem& /*problem*/) const {
  }
  // ... and a cluster below FUEL's size thresholds that the tour visits with the large ones
  // instead of after them. FUEL promotes none.
  virtual bool promoted(const PlanContext& /*ctx*/, const FrontierClusters::Cluster& /*cluster*/) const {
    return false;
  }
  // ... and with fuel.latency_tour, the weight of a site in the tour's latency (FUEL's tour has
  // none; the latency tour's is what the representative viewpoint covers, `coverage`).
  virtual double latency_weight(const PlanContext& /*ctx*/, const FrontierClusters::Cluster& /*cluster*/,
                                double coverage) const {
    return coverage;
  }

 private:
  struct ClusterState {
    std::vector<Viewpoint> views;
    int64_t sampled_cycle = 0;
    // Travel distances (m) from a representative to other clusters' representatives, each kept
    // with both positions so a changed representative is noticed.
    Eigen::Vector3d row_from = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    std::map<int64_t, std::pair<Eigen::Vector3d, double>> row;
  };
  // A cluster as the tour sees it this plan.
  struct Site {
    int64_t cluster = -1;
    std::vector<int> views;                // indices into views (top ones, reachable, not blacklisted)
    int rep = -1;                          // the representative among them
    std::vector<double> vehicle_distance;  // per view (of `views`)
  };
  struct Target {
    bool valid = false;
    int64_t cluster = -1;
    std::vector<map::VoxelKey> voxels;  // the cluster's when chosen
    int64_t planned_utime = 0;
    Goal goal;
    bool committed = false;  // flown until reached: see given_up_
  };
  struct Planned {
    Goal goal;
    int64_t cluster = -1;
    double tour_cost = 0.0;
    int site = -1;  // index into sites_ of the goal's cluster
    bool minor_only = false;  // the tour had no cluster of FUEL's size left (major_coverage)
  };

  void update_clusters(PlanContext& ctx);
  bool eligible(const PlanContext& ctx, const map::VoxelKey& k) const;
  bool blacklisted(const Eigen::Vector3d& p, int64_t cycle) const;
  // The last cycle of the bans on p (-1 when none is in force).
  int64_t ban_end(const Eigen::Vector3d& p, int64_t cycle) const;
  // Steps 3-6; `keep` (a cluster id or -1): also the cost of the best tour visiting it first.
  // When `keeps` (given the plan and that cost) says a plan only confirms the target being flown,
  // the plan comes without its path: the search to the view is not made.
  using Keeps = std::function<bool(const Planned&, double keep_cost)>;
  std::optional<Planned> plan_tour(PlanContext& ctx, int64_t keep, double* keep_cost, std::string* reason,
                                   int64_t* waiting, const Keeps& keeps);
  void compute_rows(PlanContext& ctx);
  double site_distance(int a, int b) const;  // representative to representative, m
  double view_distance(int a, int va, int b, int vb) const;
  // The cluster that now holds most of the target's voxels (-1 when none does).
  int64_t successor(const Target& t) const;
  double remaining_fraction(const PlanContext& ctx, const Target& t) const;

  // fuel.square_clearance: the interior waypoints near an obstacle hold the direction of travel.
  void square_near_obstacles(const std::vector<Eigen::Vector3d>& waypoints, std::vector<double>& yaws) const;
  // A path as far along the coarse path `guide` (vehicle to view) as A* reaches, at least
  // 1 m from the vehicle; `yaw` looks along the guide from its end. False when none is.
  bool approach(const std::vector<Eigen::Vector3d>& guide, CycleCounters* counters,
                std::vector<Eigen::Vector3d>& out, double& yaw);

  PlannerConfig config_;
  CollisionChecker checker_;
  GainEvaluator gains_;
  ViewpointSampler sampler_;
  GridSearch search_;
  FrontierClusters clusters_;
  std::map<int64_t, ClusterState> state_;
  std::vector<map::VoxelKey> dirty_;
  bool rebuild_ = true;
  struct Banned {
    Eigen::Vector3d position;
    int64_t until_cycle;
  };
  std::vector<Banned> blacklist_;
  // Places of goals the vehicle reached, with how many times after their skip had ended, and of
  // views no path was found to while recovering: the kStrikes-th time a place is banned for good
  // (its cluster's voxels cannot be seen from there, or it cannot be reached), and a ban for good
  // does not hold DONE back.
  std::vector<std::pair<Eigen::Vector3d, int>> strikes_;
  static constexpr int kStrikes = 2;
  // Views without a path to them, with how many times (approach()): the first kApproaches times
  // the vehicle flies toward them, then they are skipped.
  std::vector<std::pair<Eigen::Vector3d, int>> approaches_;
  static constexpr int kApproaches = 3;
  // Places of targets given up before they were reached (another target chosen), with how many
  // times. Once only small clusters are left (none of FUEL's size), a place given up kCommit
  // times is flown until reached (or until its view is no longer free) when it is chosen again,
  // whatever the replans say: small clusters each given up on the way for another far one were
  // never reached, so never skipped, and a 280 m² world's process set flew 680 m between them
  // to the time limit after its map had stopped growing. Not earlier: giving places up is how
  // the tour follows the map (committing there cost 5-14 s of Time_95 in env1-3).
  std::vector<std::pair<Eigen::Vector3d, int>> given_up_;
  static constexpr int kCommit = 2;
  int64_t cycle_ = 0;  // the cycle of the last plan
  static constexpr int64_t kForGood = std::numeric_limits<int64_t>::max();
  Target target_;
  bool switch_ = false;
  Goal look_;                   // the turn in place being flown (before the first tour goal)
  int looks_ = 0;               // turns made so far
  bool toured_ = false;         // a tour goal was chosen once
  int64_t skipped_until_ = -1;  // this plan's PlanOutcome::skipped_until
  std::string replan_reason_;
  // This plan's sites and tour (for the roadmap view).
  std::vector<Site> sites_;
  std::vector<int64_t> tour_;
  Eigen::Vector3d vehicle_ = Eigen::Vector3d::Zero();
  double vehicle_yaw_ = 0.0;
  // The vehicle's velocity and turn rate, from its poses at the last two plans (FUEL reads them
  // from its trajectory); vehicle_ and vehicle_yaw_ are where they take it by the time a plan is
  // released.
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  double yaw_speed_ = 0.0;
  Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();
  double last_yaw_ = 0.0;
  int64_t last_utime_ = -1;
  // The first leg's cost from the vehicle to p: travel time plus the turn of the velocity.
  double first_leg(double distance, const Eigen::Vector3d& p, double yaw) const;
};

// `waypoints` with points added evenly on every segment longer than `max_length` (m), so that no
// segment is: the controller rejects a path with a segment longer than its max_segment_length
// (10 m), and FUEL's straight line of sight to a viewpoint across a long room can be longer.
std::vector<Eigen::Vector3d> split_long_segments(const std::vector<Eigen::Vector3d>& waypoints, double max_length);

// Yaws for a path flown by FUEL: from `start_yaw` toward `goal_yaw` (the shorter way) as fast as
// `yaw_rate` allows at `velocity` along the path, so the camera looks at the goal's cluster as
// early as it can; the last waypoint has goal_yaw.
std::vector<double> turn_early_yaws(const std::vector<Eigen::Vector3d>& waypoints, double start_yaw,
                                    double goal_yaw, double velocity, double yaw_rate);

}  // namespace semx::planner
