#include "semx/planner/aep_strategy.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "semx/core/angles.hpp"
#include "semx/core/stopwatch.hpp"
#include "semx/planner/travel_cost.hpp"

namespace semx::planner {

using map::VoxelKey;

AepStrategy::AepStrategy(const PlannerConfig& config)
    : config_(config), gains_(config.gain), global_(config, false), cache_(config.roadmap.max_edge_length) {}

void AepStrategy::reset() {
  global_.reset();
  cache_.clear();
  changed_blocks_.clear();
  cache_reset_ = false;
  tree_.clear();
  best_ = -1;
  fallback_ = false;
}

void AepStrategy::on_map_changes(const std::vector<map::VoxelChange>& changes) {
  global_.on_map_changes(changes);
  for (const map::VoxelChange& c : changes) changed_blocks_.insert(map::block_of(c.key));
}

void AepStrategy::on_gain_invalidated(const std::vector<map::VoxelKey>& keys) {
  global_.on_gain_invalidated(keys);
  for (const VoxelKey& k : keys) changed_blocks_.insert(map::block_of(k));
}

void AepStrategy::on_map_reset() {
  global_.on_map_reset();
  cache_reset_ = true;
}

void AepStrategy::mark_cache_stale() {
  if (cache_reset_) {
    cache_.clear();
  } else if (!changed_blocks_.empty() && checker().grid()) {
    const double res = checker().grid()->resolution();
    const double block = map::kBlockSize * res;
    const double radius = config_.gain.max_range + 0.5 * block * std::sqrt(3.0) + res;
    for (const VoxelKey& b : changed_blocks_) {
      const Eigen::Vector3d c((b.x + 0.5) * block, (b.y + 0.5) * block, (b.z + 0.5) * block);
      for (int64_t id : cache_.nearest(c, -1, radius)) cache_.node(id).gain_stale = true;
    }
  }
  changed_blocks_.clear();
  cache_reset_ = false;
}

void AepStrategy::gain_of(PlanContext& ctx, TreeNode& n) {
  const std::vector<int64_t> near = cache_.nearest(n.position, 1, config_.aep.cache_radius);
  if (!near.empty()) {
    RoadmapNode& c = cache_.node(near.front());
    if (!c.gain_stale && c.gain.valid) {
      n.gain = c.gain;
      return;
    }
    cache_.remove_node(near.front());
  }
  core::Stopwatch w;
  GainStats stats;
  n.gain = gains_.evaluate(*ctx.grid, n.position, &stats);
  ctx.counters->gain_evaluations += stats.evaluations;
  ctx.counters->rays += stats.rays;
  ctx.counters->ray_steps += stats.steps;
  ctx.counters->gain_ms += w.ms();
  const int64_t id = cache_.add_node(n.position);
  cache_.node(id).gain = n.gain;
  cache_.node(id).gain_stale = false;
}

PlanOutcome AepStrategy::plan(PlanContext& ctx) {
  CollisionChecker& checker = this->checker();
  checker.set_grid(ctx.grid);
  gains_.set_ignored(ctx.unobservable);
  checker.reset_counters();
  mark_cache_stale();
  // The global graph: prune, and add the vehicle's pose (kept as a backbone node later).
  global_.process_map_changes(ctx);
  global_.insert_root(ctx);

  tree_.clear();
  best_ = -1;
  fallback_ = false;
  TreeNode root;
  root.position = ctx.pose.position;
  gain_of(ctx, root);
  tree_.push_back(root);

  const SamplingConfig& s = config_.sampling;
  const AepConfig& a = config_.aep;
  const int init_nodes = a.init_nodes > 0 ? a.init_nodes : s.samples;
  const int max_nodes = std::max(init_nodes, a.max_nodes);
  const int attempts = max_nodes * s.max_attempts_factor;
  int kept = 0;
  bool informative = false;  // a tree node's gain reached g_zero: stop at init_nodes
  auto more = [&] { return kept < init_nodes || (kept < max_nodes && !informative); };
  auto edge_ok = [&](int from, const Eigen::Vector3d& p) {
    ++ctx.counters->edges_checked;
    const Eigen::Vector3d& q = tree_[static_cast<size_t>(from)].position;
    return from == 0 ? checker.root_edge_free(q, p) : checker.edge_free(q, p);
  };
  for (int i = 0; i < attempts && more(); ++i) {
    ++ctx.counters->samples_drawn;
    core::Stopwatch sw;
    const Eigen::Vector3d c = ctx.pose.position;
    double z_lo = std::max(c.z() - s.local_height, s.z_min), z_hi = std::min(c.z() + s.local_height, s.z_max);
    if (!(z_lo <= z_hi)) z_lo = s.z_min, z_hi = s.z_max;
    const double x = ctx.rng->uniform(c.x() - a.radius, c.x() + a.radius);
    const double y = ctx.rng->uniform(c.y() - a.radius, c.y() + a.radius);
    const Eigen::Vector3d q(x, y, ctx.rng->uniform(z_lo, z_hi));
    const int near = nearest_tree_node(tree_, q);
    const Eigen::Vector3d from = tree_[static_cast<size_t>(near)].position;
    const double len = (q - from).norm();
    if (len < 1e-6) continue;
    Eigen::Vector3d p = from + std::min(len, a.step) / len * (q - from);
    const bool node_ok = checker.centre(p);  // moved off a wall when too close (as DEP's draws)
    ctx.counters->sample_ms += sw.ms();
    if (!node_ok) continue;

    core::Stopwatch cw;
    // Choose the parent of least cost among the near nodes (RRT*).
    std::vector<int> near_set;
    for (size_t j = 0; j < tree_.size(); ++j) {
      if ((tree_[j].position - p).norm() <= a.rewire_radius) near_set.push_back(static_cast<int>(j));
    }
    int parent = -1;
    double cost = 0.0;
    if (edge_ok(near, p)) {
      parent = near;
      cost = tree_[static_cast<size_t>(near)].cost + (p - from).norm();
    }
    for (int j : near_set) {
      if (j == near) continue;
      const double c2 =
          tree_[static_cast<size_t>(j)].cost + (p - tree_[static_cast<size_t>(j)].position).norm();
      if ((parent < 0 || c2 < cost) && edge_ok(j, p)) {
        parent = j;
        cost = c2;
      }
    }
    if (parent < 0) {
      ctx.counters->connect_ms += cw.ms();
      continue;
    }
    TreeNode n;
    n.position = p;
    n.parent = parent;
    n.cost = cost;
    tree_.push_back(n);
    const int id = static_cast<int>(tree_.size()) - 1;
    // Rewire: near nodes reached more cheaply through the new one.
    for (int j : near_set) {
      if (j == 0 || j == parent) continue;
      TreeNode& m = tree_[static_cast<size_t>(j)];
      const double c2 = cost + (m.position - p).norm();
      if (c2 + 1e-9 < m.cost && (++ctx.counters->edges_checked, checker.edge_free(p, m.position))) {
        const double delta = c2 - m.cost;
        m.parent = id;
        // Costs of the subtree below j drop by the same amount.
        for (size_t k = 0; k < tree_.size(); ++k) {
          for (int up = static_cast<int>(k); up >= 0; up = tree_[static_cast<size_t>(up)].parent) {
            if (up == j) {
              tree_[k].cost += delta;
              break;
            }
          }
        }
      }
    }
    ctx.counters->connect_ms += cw.ms();
    gain_of(ctx, tree_.back());
    const double g = tree_.back().gain.gain;
    informative = informative || (g >= a.g_zero && g >= config_.gain.min_gain);
    ++kept;
    ++ctx.counters->nodes_added;
    ++ctx.counters->edges_added;
  }

  core::Stopwatch sw;
  double best_value = -1.0, best_gain = 0.0;
  for (size_t i = 0; i < tree_.size(); ++i) {
    TreeNode& t = tree_[i];
    t.value = t.gain.gain * std::exp(-a.lambda * t.cost);
    best_gain = std::max(best_gain, t.gain.gain);
    if (t.gain.gain < config_.gain.min_gain) continue;
    if (i == 0 && core::yaw_distance(ctx.pose.yaw, t.gain.yaw) < config_.loop.yaw_tolerance) continue;
    if (t.value > best_value) {
      best_value = t.value;
      best_ = static_cast<int>(i);
    }
  }
  ctx.counters->search_settled += static_cast<int64_t>(tree_.size());
  ctx.counters->search_ms += sw.ms();

  // Feed the global graph with the informative tree nodes (their gains travel along).
  for (size_t i = 1; i < tree_.size(); ++i) {
    if (tree_[i].gain.gain < config_.gain.min_gain) continue;
    const int64_t id = global_.try_insert(ctx, tree_[i].position);
    if (id >= 0) {
      global_.graph().node(id).gain = tree_[i].gain;
      global_.graph().node(id).gain_stale = false;
      global_.graph().node(id).gain_cycle = ctx.cycle;
    }
  }

  PlanOutcome out;
  if (best_ >= 0 && tree_[static_cast<size_t>(best_)].gain.gain >= a.g_zero) {
    out.goal = first_edge_goal(tree_, best_, ctx.pose, config_.cost);
  } else {
    // Frontier fallback over the global graph.
    fallback_ = true;
    const double lambda = a.lambda;
    const DepStrategy::ScoreFn score = [lambda](double gain, double, double distance, double) {
      return gain * std::exp(-lambda * distance);
    };
    std::string reason;
    out.goal = global_.select_goal(ctx, score, &reason, &out.unreachable_informative);
    if (!out.goal.valid) {
      // Nothing cached is informative any more: grow the graph toward the frontier clusters (as
      // AEP plans to its cached frontier points) as DEP recovers, half the draws around the
      // vehicle to reach them, joined by the bridge, and look again.
      // Without this the vehicle stopped in env2's first rooms (62 %) with doors still open.
      global_.sample(ctx, 0.5, 2);
      global_.bridge(ctx);
      out.goal = global_.select_goal(ctx, score, &reason, &out.unreachable_informative);
    }
    if (!out.goal.valid) {
      std::ostringstream r;
      r << "local gain " << best_gain << " below g_zero " << a.g_zero << "; fallback: " << reason;
      out.reason = r.str();
    }
  }
  ctx.counters->box_checks += checker.box_checks();
  checker.reset_counters();
  return out;
}

RoadmapView AepStrategy::roadmap(const Goal* goal) const {
  if (fallback_) return global_.roadmap(goal);
  return tree_view(tree_, best_, best_ < 0 ? -1 : first_on_branch(tree_, best_));
}

}  // namespace semx::planner
