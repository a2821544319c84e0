// DEP: the incremental roadmap of the paper (§III-D, Fig. 3) with the semantic reward (semantic-dep)
// or without it (dep).
//
// Each cycle:
//  1. map changes since the last cycle: nodes within sensor range of a changed 16³ block get
//     their gain marked stale; nodes and edges near voxels that became occupied or unknown are
//     re-checked and removed when they collide (the roadmap never keeps a blocked edge);
//  2. the vehicle's pose becomes the root node, connected to its k nearest nodes (root_edge_free);
//     the previous root stays as an ordinary node when it is collision-free and not crowding
//     another node;
//  3. up to `samples` candidates are drawn (Sampler), each kept when node_free, at least
//     min_node_distance from every node and connected by at least one collision-free edge to its
//     k nearest nodes within max_edge_length;
//  4. Dijkstra from the root gives each node its path length d;
//  5. scores (G + R_sem) / T_path of the reachable nodes are ranked lazily: new nodes are
//     evaluated, a stale node is re-evaluated only when its cached score is the best left (its
//     gain can only have shrunk as the map filled in, up to frontier re-classification), so few
//     gains are recomputed per cycle. Nodes with G < min_gain are not goals (the reward only
//     ranks informative nodes), nor nodes that need neither a move nor a turn;
//  6. the best node is the goal; its roadmap path, with yaws turning linearly in arc length to the
//     goal's yaw, is the plan. The root itself may be the goal: a turn in place.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "semx/planner/collision_checker.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/roadmap.hpp"
#include "semx/planner/sampler.hpp"
#include "semx/planner/strategy.hpp"

namespace semx::planner {

class DepStrategy : public Strategy {
 public:
  DepStrategy(const PlannerConfig& config, bool semantic);
  // m: while recovering, a passage node may stand this close to other nodes (try_insert).
  static constexpr double kPassageSpacing = 0.15;

  void on_map_changes(const std::vector<map::VoxelChange>& changes) override;
  void on_map_reset() override;
  void on_gain_invalidated(const std::vector<map::VoxelKey>& keys) override;
  PlanOutcome plan(PlanContext& ctx) override;
  std::optional<double> goal_score(PlanContext& ctx, const Goal& goal) override;
  void reject_goal(const Goal& goal, int64_t until_cycle) override;
  bool receding_horizon() const override { return false; }
  RoadmapView roadmap(const Goal* goal) const override;
  void reset() override;

  // ---- building blocks (AEP's global graph uses them too) ----
  // Step 1: stale gains, pruning.
  void process_map_changes(PlanContext& ctx);
  // Step 2: returns the root's id.
  int64_t insert_root(PlanContext& ctx);
  // Step 3 for one position: the new node's id, or -1 when it was not kept.
  int64_t try_insert(PlanContext& ctx, const Eigen::Vector3d& p);
  // The k nearest nodes within max_edge_length (but `exclude`) that a collision-free edge joins
  // to p, with the edges' lengths.
  std::vector<std::pair<int64_t, double>> free_links(PlanContext& ctx, const Eigen::Vector3d& p,
                                                     int64_t exclude = -1);
  // Whether an edge from node `id` to p passes the check (the root's rule from the root).
  bool link_free(PlanContext& ctx, int64_t id, const Eigen::Vector3d& p);
  // Adds a node at p joined to `links`; returns its id.
  int64_t add_linked_node(PlanContext& ctx, const Eigen::Vector3d& p, bool passage,
                          const std::vector<std::pair<int64_t, double>>& links);
  // A passage node at p (id, or -1 when it connected to nothing yet) and an approach node on each
  // side of its doorway, on the line straight through it; returns the passage node's id or -1.
  int64_t add_approaches(PlanContext& ctx, const Eigen::Vector3d& p, int64_t id);
  // The roadmap path to a reached node as the vehicle flies it: waypoints, and yaws turning to
  // the node's best yaw with the doorway holds; `held` when any was held.
  struct FlownPath {
    std::vector<Eigen::Vector3d> waypoints;
    std::vector<double> yaws;
    bool held = false;
  };
  // Facing `yaw` at the end, or the node's own yaw without it.
  FlownPath flown_path(const PlanContext& ctx, int64_t id, std::optional<double> yaw = std::nullopt) const;
  // Sets the yaws at each passage node of a path and at the waypoints either side of it to the
  // direction of travel through it; true when it held any.
  bool hold_heading_through_doorways(const std::vector<int64_t>& path, const std::vector<Eigen::Vector3d>& w,
                                     std::vector<double>& yaws) const;
  // Step 3: up to sampling.samples new nodes from draws around the vehicle and the frontier
  // clusters (`frontier_fraction` of them around clusters; `attempts_scale` x the checks).
  void sample(PlanContext& ctx, double frontier_fraction, int attempts_scale);
  // Candidates between parts of the roadmap the root cannot reach and the nearest reachable
  // nodes (sampling.bridge_attempts per cycle).
  void bridge(PlanContext& ctx);
  // Recovering: edges again between each unreachable node and the nearest reachable node within
  // an edge's length, where they pass the edge check now; and approach nodes again (once per
  // recovery) for each passage node within an edge's length of the other side of the cut.
  // Returns the edges and approach nodes added.
  int relink(PlanContext& ctx, const Roadmap::Search& reach);
  // Steps 4-6 with a given score of (gain, reward, path length, yaw change); returns the goal.
  using ScoreFn = std::function<double(double gain, double reward, double distance, double yaw_change)>;
  // `unreachable` (optional) counts the nodes with gain >= min_gain the root cannot reach. With
  // `sweep` a node is scored at the yaw whose turn from the vehicle's heading, counting what it
  // sweeps, scores best (GainConfig::sweep); otherwise at its best window.
  // `tier` (optional): a node of a higher tier outranks every node of a lower one (the ordering
  // rules of semantic_room_strategy.hpp); it is called after the search, so last_search() holds
  // this cycle's paths. Without it, cost.local_first decides the tiers.
  // With `flown` (ctx.flown, from plan()) the ranking stops, answering no goal, once no node left
  // in it can score above ctx.switch_factor times the flown goal's goal_score(): the main loop
  // would keep that goal whatever the ranking answered, and the stale gains below that bar are
  // not refreshed (the same flights, fewer gain evaluations). Only where the answer is the
  // ranking's best node by score: no tiers, no local_first, no pockets.
  using TierFn = std::function<int(int64_t id)>;
  Goal select_goal(PlanContext& ctx, const ScoreFn& score, std::string* reason,
                   int64_t* unreachable = nullptr, bool sweep = false, const TierFn* tier = nullptr,
                   const Goal* flown = nullptr);
  // One cycle (plan()) with goals ranked by `tier` first (nullptr: plan() itself).
  PlanOutcome plan_with(PlanContext& ctx, const TierFn* tier);
  // The paper's score (G + R_sem) / T_path (travel_cost.hpp).
  ScoreFn paper_score() const;
  void evaluate_gain(PlanContext& ctx, int64_t id);

  // The path length node `id` is scored with: this cycle's search plus what searched() added.
  double scored_distance(int64_t id) const {
    const size_t i = static_cast<size_t>(id);
    return search_.distance[i] + (i < extra_distance_.size() ? extra_distance_[i] : 0.0);
  }

  const Roadmap& graph() const { return graph_; }
  Roadmap& graph() { return graph_; }
  int64_t root() const { return root_; }
  const PlannerConfig& config() const { return config_; }
  const Roadmap::Search& last_search() const { return search_; }
  CollisionChecker& checker() { return checker_; }
  GainEvaluator& gains() { return gains_; }

 protected:
  // Called in select_goal right after this cycle's search (last_search() holds it): a subclass
  // may fill extra_distance_ (m per slot, added to the path length a node is scored with).
  virtual void searched(PlanContext& /*ctx*/) {}
  std::vector<double> extra_distance_;

 private:
  // What a node is scored with: a yaw, the gain counted for it, and the score.
  struct View {
    double yaw = 0.0;
    double gain = 0.0;
    double reward = 0.0;
    double score = 0.0;
  };
  View view_of(PlanContext& ctx, const ScoreFn& score, int64_t id, bool sweep) const;
  // R_sem at p with this cycle's region factors (0 for plain DEP).
  double reward_at(const PlanContext& ctx, const Eigen::Vector3d& p, double yaw) const;
  // Each region's 1 + κ U_i (config reward.unexplored_weight), or a door's a_i + κ_p U_i
  // (reward.passage_weight), for this cycle's regions.
  void update_region_factors(PlanContext& ctx);
  // Some voxel of obstacle_voxels_ has its centre within `radius` of the segment a-b.
  bool obstacle_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double res) const;
  bool nothing_to_do(PlanContext& ctx, int64_t id, double yaw) const;
  // The end game (loop.end_game_gain): whether no reachable node's gain (cached: an upper bound)
  // reaches it after select_goal; and then the first stop of the shortest open tour from the
  // vehicle through the informative nodes, one per end_game_site_spacing (invalid when none).
  bool in_end_game(PlanContext& ctx) const;
  Goal tour_goal(PlanContext& ctx, const ScoreFn& score, int* stops);
  // Pockets before a far goal (loop.pocket_detour): the first stop of the shortest tour from the
  // vehicle through informative nodes to `far` (the score's goal) whose time exceeds the direct
  // trip's by at most pocket_detour x that trip; invalid when no pocket fits. `stops`: the pockets.
  Goal pocket_goal(PlanContext& ctx, const Goal& far, const ScoreFn& score, int* stops);
  // Recovery (loop.cut_looks): the reachable node nearest an unreachable node joined to an
  // informative one, with no occupied voxel on the line between them and not within 1 m of a
  // place looked from before, as a goal facing that node; invalid when none. Uses
  // this cycle's search_.
  Goal cut_look_goal(PlanContext& ctx) const;
  // A tour's stop as the goal: the node at its best window, the roadmap path to it.
  Goal stop_goal(PlanContext& ctx, const ScoreFn& score, int64_t id);

  PlannerConfig config_;
  bool semantic_;
  CollisionChecker checker_;
  GainEvaluator gains_;
  Sampler sampler_;
  Roadmap graph_;
  int64_t root_ = -1;
  std::set<map::VoxelKey> changed_blocks_;  // since the last cycle
  std::set<int64_t> reapproached_;          // passage nodes given approaches in this recovery
  int idle_cycles_ = 0;                     // cycles that needed a goal and found none, in a row
  // Places looked across a cut from, for the whole run: a look that did not open the cut would
  // not open it the next time either (the 396 m² world with noise looked from the same three
  // places again after each goal between them), and a cut that came back there has other places.
  std::vector<Eigen::Vector3d> looked_;
  int looks_now_ = 0;  // looks since the last real goal
  // Voxels that became occupied or unknown since the last cycle, by block.
  std::map<map::VoxelKey, std::vector<map::VoxelKey>> obstacle_voxels_;
  bool full_reset_ = false;
  // The last cycle's search and per-slot values, for goal_score() and the roadmap view.
  Roadmap::Search search_;
  std::vector<double> reward_, cost_, score_, yaw_, view_gain_;
  mutable std::vector<double> sweeps_;  // scratch: one node's sweep gains
  std::vector<double> region_factor_;   // one per region of ctx.regions this cycle
  // ctx.regions with the doors active when passage_weight is on (their factor says how much).
  std::vector<SemanticRegion> cycle_regions_;
};

}  // namespace semx::planner
