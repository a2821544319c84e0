#include "semx/planner/nbv_strategy.hpp"

#include <cmath>
#include <sstream>

#include "semx/core/angles.hpp"
#include "semx/core/stopwatch.hpp"
#include "semx/planner/travel_cost.hpp"

namespace semx::planner {

int nearest_tree_node(const std::vector<TreeNode>& tree, const Eigen::Vector3d& p) {
  int best = -1;
  double best_d = 0;
  for (size_t i = 0; i < tree.size(); ++i) {
    const double d = (tree[i].position - p).squaredNorm();
    if (best < 0 || d < best_d) {
      best = static_cast<int>(i);
      best_d = d;
    }
  }
  return best;
}

int first_on_branch(const std::vector<TreeNode>& tree, int node) {
  if (node <= 0) return node;
  while (tree[static_cast<size_t>(node)].parent > 0) node = tree[static_cast<size_t>(node)].parent;
  return node;
}

RoadmapView tree_view(const std::vector<TreeNode>& tree, int best, int first) {
  RoadmapView v;
  std::vector<bool> on_branch(tree.size(), false);
  for (int i = best; i >= 0; i = tree[static_cast<size_t>(i)].parent)
    on_branch[static_cast<size_t>(i)] = true;
  for (size_t i = 0; i < tree.size(); ++i) {
    const TreeNode& t = tree[i];
    RoadmapView::Node n;
    n.id = static_cast<int64_t>(i);
    n.position = t.position;
    n.yaw = t.gain.yaw;
    n.gain = t.gain.gain;
    n.cost = t.cost;
    n.score = t.value;
    if (i == 0) n.flags |= kFlagRoot;
    if (static_cast<int>(i) == first) n.flags |= kFlagGoal;
    if (on_branch[i]) n.flags |= kFlagOnPath;
    if (t.gain.valid && t.gain.counts[1] + t.gain.counts[2] > 0) n.flags |= kFlagFrontier;
    v.nodes.push_back(n);
    if (t.parent >= 0) v.edges.emplace_back(t.parent, static_cast<int64_t>(i));
  }
  return v;
}

NbvStrategy::NbvStrategy(const PlannerConfig& config)
    : config_(config), checker_(config.collision), gains_(config.gain) {}

void NbvStrategy::evaluate(PlanContext& ctx, TreeNode& n) {
  core::Stopwatch w;
  GainStats stats;
  n.gain = gains_.evaluate(*ctx.grid, n.position, &stats);
  ctx.counters->gain_evaluations += stats.evaluations;
  ctx.counters->rays += stats.rays;
  ctx.counters->ray_steps += stats.steps;
  ctx.counters->gain_ms += w.ms();
}

PlanOutcome NbvStrategy::plan(PlanContext& ctx) {
  checker_.set_grid(ctx.grid);
  gains_.set_ignored(ctx.unobservable);
  checker_.reset_counters();
  tree_.clear();
  best_ = -1;
  TreeNode root;
  root.position = ctx.pose.position;
  evaluate(ctx, root);
  root.value = root.gain.gain;
  tree_.push_back(root);

  const SamplingConfig& s = config_.sampling;
  const int attempts = s.samples * s.max_attempts_factor;
  int kept = 0;
  for (int i = 0; i < attempts && kept < s.samples; ++i) {
    ++ctx.counters->samples_drawn;
    core::Stopwatch sw;
    const Eigen::Vector3d c = ctx.pose.position;
    const double r = config_.nbv.radius;
    double z_lo = std::max(c.z() - s.local_height, s.z_min), z_hi = std::min(c.z() + s.local_height, s.z_max);
    if (!(z_lo <= z_hi)) z_lo = s.z_min, z_hi = s.z_max;
    const double x = ctx.rng->uniform(c.x() - r, c.x() + r);
    const double y = ctx.rng->uniform(c.y() - r, c.y() + r);
    const Eigen::Vector3d q(x, y, ctx.rng->uniform(z_lo, z_hi));
    const int near = nearest_tree_node(tree_, q);
    const Eigen::Vector3d from = tree_[static_cast<size_t>(near)].position;
    const Eigen::Vector3d d = q - from;
    const double len = d.norm();
    if (len < 1e-6) continue;
    Eigen::Vector3d p = from + std::min(len, config_.nbv.step) / len * d;
    const bool node_ok = checker_.centre(p);  // moved off a wall when too close (as DEP's draws)
    ctx.counters->sample_ms += sw.ms();
    if (!node_ok) continue;
    core::Stopwatch cw;
    ++ctx.counters->edges_checked;
    const bool edge_ok = near == 0 ? checker_.root_edge_free(from, p) : checker_.edge_free(from, p);
    ctx.counters->connect_ms += cw.ms();
    if (!edge_ok) continue;
    TreeNode n;
    n.position = p;
    n.parent = near;
    n.cost = tree_[static_cast<size_t>(near)].cost + (p - from).norm();
    evaluate(ctx, n);
    n.value = tree_[static_cast<size_t>(near)].value + n.gain.gain * std::exp(-config_.nbv.lambda * n.cost);
    tree_.push_back(n);
    ++kept;
    ++ctx.counters->nodes_added;
    ++ctx.counters->edges_added;
  }

  PlanOutcome out;
  // The best branch by value, among nodes whose own gain makes them worth visiting.
  core::Stopwatch sw;
  double best_value = -1.0, best_gain = 0.0;
  for (size_t i = 0; i < tree_.size(); ++i) {
    best_gain = std::max(best_gain, tree_[i].gain.gain);
    if (tree_[i].gain.gain < config_.gain.min_gain) continue;
    if (i == 0 && core::yaw_distance(ctx.pose.yaw, tree_[0].gain.yaw) < config_.loop.yaw_tolerance) continue;
    if (tree_[i].value > best_value) {
      best_value = tree_[i].value;
      best_ = static_cast<int>(i);
    }
  }
  ctx.counters->search_settled += static_cast<int64_t>(tree_.size());
  ctx.counters->search_ms += sw.ms();
  ctx.counters->box_checks += checker_.box_checks();
  checker_.reset_counters();
  if (best_ < 0) {
    std::ostringstream r;
    r << "no tree node with gain >= " << config_.gain.min_gain << " (" << tree_.size() << " nodes, best gain "
      << best_gain << ")";
    out.reason = r.str();
    return out;
  }
  out.goal = first_edge_goal(tree_, best_, ctx.pose, config_.cost);
  return out;
}

Goal first_edge_goal(const std::vector<TreeNode>& tree, int best, const VehiclePose& pose,
                     const CostConfig& cost) {
  const int first = first_on_branch(tree, best);
  const TreeNode& f = tree[static_cast<size_t>(first)];
  Goal g;
  g.valid = true;
  g.position = f.position;
  g.yaw = f.gain.yaw;
  g.gain = f.gain.gain;
  g.cost = travel_time(f.cost, pose.yaw, f.gain.yaw, cost);
  g.score = tree[static_cast<size_t>(best)].value;
  g.waypoints = first == 0 ? std::vector<Eigen::Vector3d>{pose.position}
                           : std::vector<Eigen::Vector3d>{pose.position, f.position};
  g.yaws = interpolate_yaws(g.waypoints, pose.yaw, g.yaw);
  return g;
}

RoadmapView NbvStrategy::roadmap(const Goal*) const {
  return tree_view(tree_, best_, best_ < 0 ? -1 : first_on_branch(tree_, best_));
}

}  // namespace semx::planner
