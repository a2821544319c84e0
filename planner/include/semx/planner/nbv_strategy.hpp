// NBV: receding-horizon next-best-view planning (Bircher et al., ICRA 2016), the paper's first
// baseline, on the same map, sensor model, gain and collision checks as DEP.
//
// Each cycle a new RRT is grown from the vehicle: up to `samples` nodes, each by steering the
// nearest tree node toward a uniform draw in a box of half width nbv.radius around the vehicle
// (nbv.step at most), kept when node_free and its edge is free. A node's value is its branch's
// Σ G(n)·exp(-λ·c(n)) (c the path length from the root). The vehicle flies the first edge of the
// branch of the best node, at that node's best yaw, and plans again on arrival.
// Simplifications: yaw is each node's best gain window (NBVP samples yaw); no tree is kept
// between cycles (NBVP re-seeds the best branch); no semantic reward.
#pragma once

#include <vector>

#include "semx/planner/collision_checker.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/strategy.hpp"

namespace semx::planner {

// One RRT node (NBV and AEP).
struct TreeNode {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int parent = -1;
  double cost = 0.0;   // path length from the root
  double value = 0.0;  // branch value
  NodeGain gain;
};

class NbvStrategy : public Strategy {
 public:
  explicit NbvStrategy(const PlannerConfig& config);

  // The checker's ESDF cache keeps what the changes leave true (without, it was refilled whole
  // after every update).
  void on_map_changes(const std::vector<map::VoxelChange>& changes) override {
    checker_.note_changes(changes);
  }
  void on_map_reset() override {}
  void on_gain_invalidated(const std::vector<map::VoxelKey>&) override {}
  PlanOutcome plan(PlanContext& ctx) override;
  std::optional<double> goal_score(PlanContext&, const Goal&) override { return std::nullopt; }
  void reject_goal(const Goal&, int64_t) override {}
  bool receding_horizon() const override { return true; }
  RoadmapView roadmap(const Goal* goal) const override;
  void reset() override { tree_.clear(); }

  const std::vector<TreeNode>& tree() const { return tree_; }

 private:
  void evaluate(PlanContext& ctx, TreeNode& n);

  PlannerConfig config_;
  CollisionChecker checker_;
  GainEvaluator gains_;
  std::vector<TreeNode> tree_;
  int best_ = -1;
};

// Shared by NBV and AEP: the index of the tree node nearest to p.
int nearest_tree_node(const std::vector<TreeNode>& tree, const Eigen::Vector3d& p);
// The root's child on the branch to `node` (the first edge to fly), or `node` when it is the root.
int first_on_branch(const std::vector<TreeNode>& tree, int node);
// The receding-horizon goal: the first node on the branch to `best` (its yaw and gain), scored
// with `best`'s value, reached from the vehicle's pose in one straight edge.
Goal first_edge_goal(const std::vector<TreeNode>& tree, int best, const VehiclePose& pose,
                     const CostConfig& cost);
// A tree as a roadmap view (edges parent-child), with `best` flagged GOAL and its branch ON_PATH.
RoadmapView tree_view(const std::vector<TreeNode>& tree, int best, int first);

}  // namespace semx::planner
