// AEP: autonomous exploration planning (Selin et al., RA-L 2019), the paper's second baseline, on
// the same map, sensor model, gain and collision checks as DEP.
//
// Local planning: each cycle an RRT* is grown from the vehicle (aep.step, choose-parent and
// rewiring within aep.rewire_radius, in a box of half width aep.radius): aep.init_nodes nodes
// (sampling.samples by default), then more while none has a gain of aep.g_zero, up to
// aep.max_nodes (AEP's initial and cutoff iterations).
// Gains come from a persistent cache: a tree node within aep.cache_radius of a cached position
// whose gain is not stale (no map change within sensor range since) reuses it; otherwise it is
// evaluated and cached. A node's value is G(n)·exp(-λ·c(n)); when the best local value's gain
// reaches aep.g_zero the vehicle flies the first edge of its branch (receding horizon).
// Frontier fallback: otherwise the goal is the cached high-gain position with the best
// G·exp(-λ·d) over a persistent graph (d its graph distance), and the whole path to it is flown;
// when no cached position is informative any more, the graph first grows samples around the
// frontier clusters (DEP's recovery sampling: half the draws there, half around the vehicle,
// twice the attempts).
// Simplifications: the global graph is DEP's roadmap fed with the tree nodes whose gain reaches
// min_gain and with the vehicle's past poses (AEP keeps a separate kd-tree of frontier points and
// plans to them on its RRG); the gain is DEP's yaw-binned one (AEP optimises yaw continuously
// with its own sparse ray model); no semantic reward.
#pragma once

#include <vector>

#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/nbv_strategy.hpp"

namespace semx::planner {

class AepStrategy : public Strategy {
 public:
  explicit AepStrategy(const PlannerConfig& config);

  void on_map_changes(const std::vector<map::VoxelChange>& changes) override;
  void on_map_reset() override;
  void on_gain_invalidated(const std::vector<map::VoxelKey>& keys) override;
  PlanOutcome plan(PlanContext& ctx) override;
  std::optional<double> goal_score(PlanContext&, const Goal&) override { return std::nullopt; }
  void reject_goal(const Goal& goal, int64_t until_cycle) override { global_.reject_goal(goal, until_cycle); }
  bool receding_horizon() const override { return true; }
  RoadmapView roadmap(const Goal* goal) const override;
  void reset() override;

  bool last_was_fallback() const { return fallback_; }
  size_t cache_size() const { return cache_.num_nodes(); }
  size_t tree_size() const { return tree_.size(); }  // with the root

 private:
  void gain_of(PlanContext& ctx, TreeNode& n);
  void mark_cache_stale();
  // The tree's checks use the fallback graph's checker: its ESDF cache is kept across map updates
  // (DepStrategy::on_map_changes passes them on). A checker of the tree's own was told of none,
  // so it refilled every chunk it read after each update.
  CollisionChecker& checker() { return global_.checker(); }

  PlannerConfig config_;
  GainEvaluator gains_;
  DepStrategy global_;  // the fallback graph (no sampling of its own)
  Roadmap cache_;       // cached gains at positions (no edges)
  std::set<map::VoxelKey> changed_blocks_;
  bool cache_reset_ = false;
  std::vector<TreeNode> tree_;
  int best_ = -1;
  bool fallback_ = false;
};

}  // namespace semx::planner
