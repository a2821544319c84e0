#include "semx/planner/semantic_room_strategy.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <set>

#include "semx/planner/tour_solver.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::planner {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

SemanticRoomStrategy::SemanticRoomStrategy(const PlannerConfig& config)
    : DepStrategy(config, config.room.eq6_reward), rules_(config.room) {}

bool SemanticRoomStrategy::doorway(const PlanContext& ctx, int64_t id) const {
  const RoadmapNode& n = graph().node(id);
  if (rules_.passages_bound && n.passage) return true;
  return door_near(ctx, n.position) >= 0;
}

int SemanticRoomStrategy::door_near(const PlanContext& ctx, const Eigen::Vector3d& p) const {
  if (!ctx.regions || !(rules_.door_radius > 0)) return -1;
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  const double r2 = rules_.door_radius * rules_.door_radius;
  for (size_t i = 0; i < ctx.regions->size(); ++i) {
    const SemanticRegion& s = (*ctx.regions)[i];
    // A door stays a doorway once its leaf is fully observed (active only says the leaf was seen).
    if (s.class_id != door || !s.centroid.allFinite()) continue;
    if ((p - s.centroid).head<2>().squaredNorm() <= r2) return static_cast<int>(i);
  }
  return -1;
}

int SemanticRoomStrategy::door_crossed(const PlanContext& ctx, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b) const {
  if (!rules_.cut_edges || !ctx.regions || !(rules_.door_radius > 0)) return -1;
  const int door = static_cast<int>(runtime::SemanticClass::kDoor);
  const Eigen::Vector2d a2 = a.head<2>(), ab = b.head<2>() - a2;
  const double len2 = ab.squaredNorm();
  for (size_t i = 0; i < ctx.regions->size(); ++i) {
    const SemanticRegion& s = (*ctx.regions)[i];
    if (s.class_id != door || !s.centroid.allFinite()) continue;
    const Eigen::Vector2d c = s.centroid.head<2>();
    const double t = len2 > 0 ? std::clamp((c - a2).dot(ab) / len2, 0.0, 1.0) : 0.0;
    if ((a2 + t * ab - c).squaredNorm() <= rules_.door_radius * rules_.door_radius)
      return static_cast<int>(i);
  }
  return -1;
}

void SemanticRoomStrategy::label_rooms(PlanContext& ctx) {
  const Roadmap& g = graph();
  constexpr int kUnlabelled = -2;
  room_.assign(g.slots().size(), -1);
  const Roadmap::Search& reach = last_search();
  for (const RoadmapNode& n : g.slots()) {
    if (n.alive && reach.reached(n.id) && !doorway(ctx, n.id)) room_[static_cast<size_t>(n.id)] = kUnlabelled;
  }
  int rooms = 0;
  auto flood = [&](int64_t seed) {
    std::deque<int64_t> open{seed};
    room_[static_cast<size_t>(seed)] = rooms;
    while (!open.empty()) {
      const int64_t id = open.front();
      open.pop_front();
      for (const RoadmapEdge& e : g.node(id).edges) {
        int& label = room_[static_cast<size_t>(e.to)];
        if (label != kUnlabelled) continue;
        if (door_crossed(ctx, g.node(id).position, g.node(e.to).position) >= 0) continue;
        label = rooms;
        open.push_back(e.to);
      }
    }
    ++rooms;
  };
  // The vehicle's room is room 0 (none when it stands in a doorway).
  const bool in_room = root() >= 0 && room_[static_cast<size_t>(root())] == kUnlabelled;
  if (in_room) flood(root());
  vehicle_room_ = in_room ? 0 : -1;
  for (const RoadmapNode& n : g.slots()) {
    if (room_[static_cast<size_t>(n.id)] == kUnlabelled) flood(n.id);
  }
  target_ = -1;
  if (!(rules_.finish_gain > 0)) return;
  if (!rules_.tour) {
    target_ = in_room ? 0 : -1;
    return;
  }
  choose_target(ctx, rooms);
}

void SemanticRoomStrategy::choose_target(PlanContext& ctx, int rooms) {
  // Each room's best node of finish_gain, its gain fresh (a stale gain only bounds it from above).
  std::vector<int64_t> best(static_cast<size_t>(rooms), -1);
  for (bool changed = true; changed;) {
    changed = false;
    std::fill(best.begin(), best.end(), -1);
    for (const RoadmapNode& n : graph().slots()) {
      const int r = room_[static_cast<size_t>(n.id)];
      if (r < 0 || n.passage || n.blacklisted_until >= ctx.cycle || !n.gain.valid) continue;
      if (room_gain(n) < rules_.finish_gain) continue;
      int64_t& b = best[static_cast<size_t>(r)];
      if (b < 0 || room_gain(n) > room_gain(graph().node(b))) b = n.id;
    }
    for (int64_t b : best) {
      if (b >= 0 && graph().node(b).gain_stale) {
        evaluate_gain(ctx, b);
        changed = true;
      }
    }
  }
  std::vector<int> candidates;  // rooms, in the tour's node order 1..m
  for (int r = 0; r < rooms; ++r)
    if (best[static_cast<size_t>(r)] >= 0) candidates.push_back(r);
  if (candidates.size() <= 1) {
    target_ = candidates.empty() ? -1 : candidates.front();
    return;
  }
  // Travel between the rooms' best nodes along the roadmap; from the vehicle, this cycle's search.
  const int m = static_cast<int>(candidates.size());
  TourProblem p;
  p.n = m + 1;
  p.cost.assign(static_cast<size_t>(p.n * p.n), 0.0);
  const Roadmap::Search& from_root = last_search();
  for (int j = 0; j < m; ++j)
    p.cost[static_cast<size_t>(j + 1)] = from_root.distance[static_cast<size_t>(best[static_cast<size_t>(candidates[j])])];
  for (int i = 0; i < m; ++i) {
    const Roadmap::Search s = graph().shortest_paths(best[static_cast<size_t>(candidates[i])]);
    ctx.counters->search_settled += s.settled;
    for (int j = 0; j < m; ++j) {
      const double d = s.distance[static_cast<size_t>(best[static_cast<size_t>(candidates[j])])];
      p.cost[static_cast<size_t>((i + 1) * p.n + (j + 1))] = std::isfinite(d) ? d : 1e9;
    }
  }
  const Tour t = solve_open_tour(p, 10);
  target_ = t.order.empty() ? -1 : candidates[static_cast<size_t>(t.order.front() - 1)];
}

void SemanticRoomStrategy::searched(PlanContext& ctx) {
  labelled_in_search_ = rules_.return_weight > 0;
  if (!labelled_in_search_) return;
  label_rooms(ctx);
  const Roadmap& g = graph();
  const Roadmap::Search& reach = last_search();
  // Each room's entry: the nearest (from the vehicle) way in, a doorway node next to one of its
  // nodes or its first node across a cut edge; and its ways in, told apart by their door.
  std::vector<double> entry;
  std::vector<std::set<int64_t>> ways;
  for (const RoadmapNode& n : g.slots()) {
    const int r = room_[static_cast<size_t>(n.id)];
    if (r < 0 || r == vehicle_room_) continue;
    if (entry.size() <= static_cast<size_t>(r)) {
      entry.resize(static_cast<size_t>(r) + 1, kInf);
      ways.resize(static_cast<size_t>(r) + 1);
    }
    for (const RoadmapEdge& e : n.edges) {
      const int other = room_[static_cast<size_t>(e.to)];
      if (other == r || !reach.reached(e.to)) continue;
      // Next to a doorway node: the way in is that node. Across a cut edge (another room): the
      // way in is this node, the first past the doorway.
      const double in =
          other == -1 ? reach.distance[static_cast<size_t>(e.to)] : reach.distance[static_cast<size_t>(n.id)];
      entry[static_cast<size_t>(r)] = std::min(entry[static_cast<size_t>(r)], in);
      if (!rules_.dead_ends_only) continue;
      const RoadmapNode& m = g.node(e.to);
      int door = other == -1 ? door_near(ctx, m.position) : door_crossed(ctx, n.position, m.position);
      // A passage node without a door is a way of its own.
      ways[static_cast<size_t>(r)].insert(door >= 0 ? door : -1 - e.to);
    }
  }
  extra_distance_.assign(g.slots().size(), 0.0);
  for (const RoadmapNode& n : g.slots()) {
    const int r = room_[static_cast<size_t>(n.id)];
    if (r < 0 || r == vehicle_room_ || static_cast<size_t>(r) >= entry.size()) continue;
    const double e = entry[static_cast<size_t>(r)];
    // A room reached without a doorway node next to it (through a gap the rooms' cut missed) has
    // no way back to charge.
    if (!std::isfinite(e)) continue;
    // A room with a second way out known is passed through, not left the way it was entered.
    if (rules_.dead_ends_only && ways[static_cast<size_t>(r)].size() > 1) continue;
    extra_distance_[static_cast<size_t>(n.id)] =
        rules_.return_weight * std::max(0.0, reach.distance[static_cast<size_t>(n.id)] - e);
  }
}

DepStrategy::TierFn SemanticRoomStrategy::tiers(PlanContext& ctx, bool* labelled) {
  // Asked for after select_goal's search: the rooms are labelled on first use, unless searched()
  // labelled them for this search already.
  return [this, &ctx, labelled](int64_t id) {
    if (!*labelled) {
      if (!labelled_in_search_) label_rooms(ctx);
      *labelled = true;
    }
    if (target_ < 0 || room_[static_cast<size_t>(id)] != target_) return 0;
    // Gains are upper bounds until re-evaluated (stale ones come back with their new gain).
    return room_gain(graph().node(id)) >= rules_.finish_gain ? 1 : 0;
  };
}

double SemanticRoomStrategy::room_gain(const RoadmapNode& n) const {
  if (!rules_.boundary_gain) return n.gain.gain;
  const GainConfig& g = config().gain;
  return g.weight_frontier * static_cast<double>(n.gain.counts[1]) +
         g.weight_surface * static_cast<double>(n.gain.counts[2]);
}

PlanOutcome SemanticRoomStrategy::plan(PlanContext& ctx) {
  bool labelled = false;
  const TierFn tier = tiers(ctx, &labelled);
  return plan_with(ctx, &tier);
}

Goal SemanticRoomStrategy::select_goal_by_rooms(PlanContext& ctx, std::string* reason) {
  bool labelled = false;
  const TierFn tier = tiers(ctx, &labelled);
  return select_goal(ctx, paper_score(), reason, nullptr, config().gain.sweep, &tier);
}

}  // namespace semx::planner
