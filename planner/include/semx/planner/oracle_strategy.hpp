// The known-map oracle (`--planner oracle`): NOT an exploration method but the reference that
// bounds one. It CHEATS: it reads the world's ground truth (truth_map.hpp; the evaluator's target
// set T and the true occupancy) and flies a tour of viewpoints chosen to see T, which no planner
// that does not know the world can do. It measures how fast the vehicle, the camera and the
// controller could map a world at all (docs/planner.md, "The known-map oracle").
//
// At its first cycle, from the vehicle's pose (nothing of the live map is used):
//   1. candidates: a lattice (oracle.spacing, oracle.height_step, heights within
//      sampling.z_min..z_max) on the true free space, each moved to the nearest voxel centre
//      around it that DEP would accept as a goal (CollisionChecker::node_free on a grid holding
//      the truth: the same body and clearance) and reachable from the vehicle;
//   2. what each sees, for each of gain.yaw_bins yaws: rays through the true map (the camera of
//      gain.*, its pinhole frustum at that yaw, z-depth within min_range..max_range, stopping at
//      true occupied voxels, a return nearer than min_range seeing nothing: the mapper's rules);
//   3. a greedy set cover (set_cover.hpp) of oracle.cover_fraction of what all candidates see of T;
//   4. a tour from the vehicle through the picked viewpoints (tour_solver.hpp), the cost of a leg
//      travel_time() (cost.*) of its path length on the true free space and its turn; paths are
//      searched on the voxels whose true clearance the checker accepts (door_clearance, bare body
//      box), charged for flying closer than oracle.preferred_clearance.
// Then it flies the tour as any planner flies its goals: a path (the search's, pulled straight
// where the clearance allows) with yaws turning to the viewpoint's, on through the following
// viewpoints (up to oracle.chain) while the heading keeps up, so the vehicle stops only where it
// must turn longer than it flies, and the last viewpoint of the path is the goal. Legs cross space the
// live map does not know yet; it trusts the truth there (trusts_own_paths), the controller checks
// its own ESDF. A viewpoint none of whose T voxels is still unknown in the live map unless it is
// the last one of the tour left to see it, is skipped. DONE after the last viewpoint.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "semx/planner/set_cover.hpp"
#include "semx/planner/strategy.hpp"
#include "semx/planner/truth_map.hpp"

namespace semx::planner {

struct OracleViewpoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  int64_t gain = 0;  // T voxels the set cover picked it for (not seen by the earlier picks)
};

// What the oracle planned, in the planner's status and log.
struct OracleSummary {
  bool ready = false;
  std::string error;       // why there is no plan
  int64_t target = 0;      // |T|
  int64_t candidates = 0;  // viewpoints on the lattice that a goal may be (reachable, free)
  int64_t observable = 0;  // voxels of T some candidate sees, at some yaw
  int64_t covered = 0;     // ... that the picked viewpoints see
  int64_t viewpoints = 0;  // picked
  int64_t cover_dropped = 0;
  int64_t first_pass = 0;  // viewpoints of the first tour (oracle.first_pass), the rest in the second
  double first_pass_exponent = 0.0;  // the e of its ratio, and whether it is flown as a tour
  bool first_pass_toured = false;
  bool first_pass_improved = false;            // reordered by the model's time to the target share
  bool first_pass_early_first = false;         // ... to the early share first (oracle.early_first_slack)
  double first_pass_before_improvement = 0.0;  // s, the model's two times summed before that
  double first_pass_target_time = 0.0;         // s, when it shows oracle.target_share of T by the model
  double first_pass_early_time = 0.0;          // s, ... oracle.early_share
  // With oracle.early_first_slack >= 0, every schedule the choice was made from, with its
  // modelled times to the early and the target share: what one flight gives up of each.
  std::string schedules;
  double tour_time = 0.0;                      // s, the tour's summed leg costs
  double tour_length = 0.0;                    // m
  bool tour_exact = false;
  double prepare_ms = 0.0;  // wall time of the whole preparation (never charged: it stands for
                            // knowing the world beforehand)
  // The candidates' views kept packed within oracle.cache_mb, their bytes, and the casts made:
  // casts well above `candidates` say that a larger cache would prepare sooner.
  int64_t views_kept = 0;
  int64_t view_bytes = 0;
  int64_t casts = 0;
  // observable / target, covered / observable.
  double observable_share() const { return target > 0 ? double(observable) / double(target) : 0.0; }
  double cover_share() const { return observable > 0 ? double(covered) / double(observable) : 0.0; }
  std::string describe() const;
};

class OracleStrategy : public Strategy {
 public:
  explicit OracleStrategy(const PlannerConfig& config);
  ~OracleStrategy() override;

  void set_truth(const TruthMap* truth) override;
  void on_map_changes(const std::vector<map::VoxelChange>&) override {}
  void on_map_reset() override {}
  void on_gain_invalidated(const std::vector<map::VoxelKey>&) override {}
  PlanOutcome plan(PlanContext& ctx) override;
  std::optional<double> goal_score(PlanContext&, const Goal&) override { return std::nullopt; }
  void reject_goal(const Goal&, int64_t) override {}
  bool receding_horizon() const override { return true; }
  bool trusts_own_paths() const override { return true; }
  RoadmapView roadmap(const Goal* goal) const override;
  void reset() override;

  // The preparation (steps 1-4 above) from a start pose; plan() runs it on its first call. False
  // (and summary().error) without a truth or a reachable start.
  bool prepare(const Eigen::Vector3d& start, double start_yaw);
  const OracleSummary& summary() const { return summary_; }
  // The viewpoints in the order flown.
  const std::vector<OracleViewpoint>& tour() const { return tour_; }
  // Index of the viewpoint being flown to (tour().size() when done), and those skipped.
  size_t next_viewpoint() const { return next_; }
  int64_t skipped() const { return skipped_; }
  // The share of T, and of its observable part, that `grid` knows (free or occupied).
  std::pair<double, double> coverage(const map::StateGrid& grid) const;
  // Path on the true free space from `from` to `to` (first waypoint `from`), empty when none.
  std::vector<Eigen::Vector3d> truth_path(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;
  // Holds the heading square to the direction of travel where a path passes close to the truth's
  // obstacles (adds a waypoint at each end of such a stretch).
  void hold_square(std::vector<Eigen::Vector3d>& path, std::vector<double>& yaws) const;
  // The T voxels (keys) viewpoint i of the tour sees at its yaw, by the oracle's camera model.
  std::vector<map::VoxelKey> seen_by(size_t i) const;

  // The problems it solved, for the tests' brute force: the candidates, what each sees (element
  // = T id, members = yaw bins), the cover's picks; the tour's cost matrix (node 0 the start, node
  // i the cover's pick i - 1) and the order flown.
  std::vector<Eigen::Vector3d> candidates() const;
  std::vector<MaskedElement> candidate_view(size_t candidate) const;
  int64_t target_ids() const;
  const std::vector<CoverPick>& picks() const { return picks_; }
  const std::vector<std::vector<double>>& tour_costs() const { return tour_costs_; }
  const std::vector<int>& tour_order() const { return tour_order_; }

 private:
  struct Model;
  PlannerConfig config_;
  const TruthMap* truth_ = nullptr;
  std::unique_ptr<Model> model_;
  OracleSummary summary_;
  std::vector<OracleViewpoint> tour_;
  std::vector<std::vector<int32_t>> tour_elements_;  // T ids each tour viewpoint sees
  std::vector<uint16_t> holders_;                    // tour viewpoints not yet flown that see each T id
  std::vector<CoverPick> picks_;
  std::vector<std::vector<double>> tour_costs_;
  std::vector<int> tour_order_;
  size_t next_ = 0;
  size_t chain_end_ = 0;  // the last viewpoint of the path being flown (its goal)
  int attempts_ = 0;      // plans toward tour_[next_]
  int64_t skipped_ = 0;
  bool prepared_ = false;
};

}  // namespace semx::planner
