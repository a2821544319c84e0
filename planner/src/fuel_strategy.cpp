#include "semx/planner/fuel_strategy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "semx/core/angles.hpp"
#include "semx/core/stopwatch.hpp"
#include "semx/map/sort_keys.hpp"
#include "semx/planner/travel_cost.hpp"

namespace semx::planner {

using map::VoxelKey;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Cells the vehicle's Dijkstra and a cluster's may settle (a whole apartment is ~10^5 at 0.2 m).
constexpr int64_t kMaxFieldCells = 4000000;
// Voxels the A* to the goal may settle: an apartment's free space at 0.1 m is ~10^6.
constexpr int64_t kMaxPathVoxels = 600000;
// ... and the A* that leaves the coarse path's corridor when the search along it failed. Such a
// failure is the field's lenient cells passing a gap A* cannot, so the wider search failed too,
// after settling its whole budget: a 0.7 s planning cycle of semantic-fuel in the 600 m² world.
// A detour around a corridor's obstacle is local: a cube of 4.6 m at 0.1 m.
constexpr int64_t kMaxDetourVoxels = 100000;
// Goals tried per plan when the chosen one has no path.
constexpr int kAttempts = 3;
// A cluster without viewpoints is sampled again after this many cycles, this many per cycle.
constexpr int64_t kResampleCycles = 8;
constexpr int kResampleClusters = 3;
constexpr int kLookTurns = 4;       // quarter turns in place at most before the first tour goal
constexpr double kSameView = 0.05;  // m and rad: a replanned view this near the target's is the same

const std::vector<Viewpoint> kNoViews;

// Counts per place (strikes_, given_up_): places within `near` of each other are one.
using PlaceCounts = std::vector<std::pair<Eigen::Vector3d, int>>;
PlaceCounts::iterator place_at(PlaceCounts& places, const Eigen::Vector3d& x, double near) {
  return std::find_if(places.begin(), places.end(),
                      [&](const auto& p) { return (p.first - x).norm() < near; });
}
// The count of the place at x, a new place counting 0.
int& count_at(PlaceCounts& places, const Eigen::Vector3d& x, double near) {
  auto it = place_at(places, x, near);
  if (it == places.end()) it = places.insert(places.end(), {x, 0});
  return it->second;
}

}  // namespace

std::vector<Eigen::Vector3d> split_long_segments(const std::vector<Eigen::Vector3d>& waypoints, double max_length) {
  if (waypoints.empty() || !(max_length > 0)) return waypoints;
  std::vector<Eigen::Vector3d> out{waypoints.front()};
  for (size_t i = 1; i < waypoints.size(); ++i) {
    const Eigen::Vector3d& a = waypoints[i - 1];
    const Eigen::Vector3d& b = waypoints[i];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / max_length)));
    for (int k = 1; k < pieces; ++k) out.push_back(a + (static_cast<double>(k) / pieces) * (b - a));
    out.push_back(b);
  }
  return out;
}

std::vector<double> turn_early_yaws(const std::vector<Eigen::Vector3d>& w, double start_yaw, double goal_yaw,
                                    double velocity, double yaw_rate) {
  std::vector<double> yaws(w.size(), core::wrap_angle(goal_yaw));
  if (w.size() < 2) return yaws;
  const double turn = core::wrap_angle(goal_yaw - start_yaw);
  double along = 0.0;
  yaws[0] = core::wrap_angle(start_yaw);
  for (size_t i = 1; i + 1 < w.size(); ++i) {
    along += (w[i] - w[i - 1]).norm();
    const double reach = yaw_rate * along / velocity;
    yaws[i] = core::wrap_angle(start_yaw + std::clamp(turn, -reach, reach));
  }
  return yaws;
}

FuelStrategy::FuelStrategy(const PlannerConfig& config)
    : config_(config),
      checker_(config.collision),
      gains_(config.gain),
      sampler_(config, checker_, gains_),
      search_(checker_, config.collision, config.fuel.search_step, config.fuel.low_clearance_penalty),
      clusters_(0.0, config.fuel.min_cluster_voxels, config.fuel.split_radius) {}

void FuelStrategy::reset() {
  clusters_.clear();
  state_.clear();
  dirty_.clear();
  rebuild_ = true;
  blacklist_.clear();
  strikes_.clear();
  approaches_.clear();
  given_up_.clear();
  cycle_ = 0;
  target_ = Target();
  switch_ = false;
  look_ = Goal();
  looks_ = 0;
  toured_ = false;
  replan_reason_.clear();
  velocity_.setZero();
  yaw_speed_ = 0.0;
  last_utime_ = -1;
  sites_.clear();
  tour_.clear();
  search_.reset();
}

void FuelStrategy::on_map_changes(const std::vector<map::VoxelChange>& changes) {
  checker_.note_changes(changes);
  search_.note_changes(changes);
  // A voxel's frontier status depends on its own state and its face neighbours' (FrontierTracker).
  for (const map::VoxelChange& c : changes) {
    dirty_.push_back(c.key);
    for (const VoxelKey& d : map::kFaceNeighbours) dirty_.push_back(c.key + d);
  }
}

void FuelStrategy::on_map_reset() {
  rebuild_ = true;
  search_.reset();
}

void FuelStrategy::on_gain_invalidated(const std::vector<map::VoxelKey>& keys) {
  dirty_.insert(dirty_.end(), keys.begin(), keys.end());
}

double FuelStrategy::first_leg(double distance, const Eigen::Vector3d& p, double yaw) const {
  double t = travel_time(distance, vehicle_yaw_, yaw, config_.cost);
  // FUEL's ViewNode::computeCost: w_dir times the angle between the velocity and the straight
  // direction to the viewpoint, added to the flight's part (here the whole lower bound).
  const Eigen::Vector3d d = p - vehicle_;
  if (velocity_.norm() > 0.1 && d.norm() > 1e-6)
    t += config_.fuel.direction_weight *
         std::acos(std::clamp(velocity_.normalized().dot(d.normalized()), -1.0, 1.0));
  return t;
}

const std::vector<Viewpoint>& FuelStrategy::viewpoints(int64_t cluster) const {
  const auto it = state_.find(cluster);
  return it == state_.end() ? kNoViews : it->second.views;
}

bool FuelStrategy::eligible(const PlanContext& ctx, const VoxelKey& k) const {
  // Voxels found unobservable (seen from a reached goal and still unknown) are nothing to visit.
  return (k.z + 0.5) * clusters_.resolution() >= config_.fuel.min_frontier_z && ctx.frontiers->contains(k) &&
         !(ctx.unobservable && ctx.unobservable->contains(k));
}

void FuelStrategy::update_clusters(PlanContext& ctx) {
  const map::StateGrid& grid = *ctx.grid;
  if (clusters_.resolution() != grid.resolution()) {
    clusters_ =
        FrontierClusters(grid.resolution(), config_.fuel.min_cluster_voxels, config_.fuel.split_radius);
    state_.clear();
    rebuild_ = true;
  }
  if (!ctx.frontiers) return;
  // eligible() with cursors: the region growing asks about every neighbour of every voxel.
  VoxelSet::Cursor frontier(ctx.frontiers->bits());
  std::optional<VoxelSet::Cursor> ignored;
  if (ctx.unobservable) ignored.emplace(*ctx.unobservable);
  const double res = grid.resolution(), z_min = config_.fuel.min_frontier_z;
  const FrontierClusters::Eligible ok = [&](const VoxelKey& k) {
    return (k.z + 0.5) * res >= z_min && frontier.contains(k) && !(ignored && ignored->contains(k));
  };
  FrontierClusters::Changes changes;
  if (rebuild_) {
    const auto& all = ctx.frontiers->voxels();
    changes = clusters_.rebuild(std::vector<VoxelKey>(all.begin(), all.end()), ok);
    rebuild_ = false;
  } else if (!dirty_.empty()) {
    map::sort_unique(dirty_);
    changes = clusters_.update(dirty_, ok);
  }
  dirty_.clear();
  for (int64_t id : changes.removed) state_.erase(id);
  core::Stopwatch w;
  auto sample = [&](int64_t id) {
    ClusterState& s = state_[id];
    // The rings' phase is the seed's (FUEL's rings start at -pi; LKH, its tour solver, draws
    // from a seed too): a run is a function of the seed, and seeds show how much one run's
    // figures owe to where the candidates happened to fall.
    const double phase = ctx.rng ? ctx.rng->uniform() : 0.0;
    s.views = sampler_.sample(grid, *clusters_.find(id), ctx.counters, phase);
    s.sampled_cycle = ctx.cycle;
    ctx.counters->samples_drawn +=
        static_cast<int64_t>(config_.fuel.view_radius_steps) * config_.fuel.view_angles;
    ctx.counters->nodes_added += static_cast<int64_t>(s.views.size());
  };
  for (int64_t id : changes.added) sample(id);
  // A cluster without a viewpoint is sampled again now and then: the space around it fills in
  // (candidates that were unknown become free) while its own voxels, which alone would make it
  // new, may not change.
  int again = 0;
  for (auto& [id, s] : state_) {
    if (again >= kResampleClusters) break;
    if (s.views.empty() && ctx.cycle - s.sampled_cycle >= kResampleCycles) {
      sample(id);
      ++again;
    }
  }
  ctx.counters->gain_ms += w.ms();
}

int64_t FuelStrategy::ban_end(const Eigen::Vector3d& p, int64_t cycle) const {
  int64_t end = -1;
  for (const Banned& b : blacklist_) {
    if (b.until_cycle >= cycle && (b.position - p).norm() < config_.fuel.min_view_distance)
      end = std::max(end, b.until_cycle);
  }
  return end;
}

bool FuelStrategy::blacklisted(const Eigen::Vector3d& p, int64_t cycle) const {
  for (const Banned& b : blacklist_) {
    if (b.until_cycle >= cycle && (b.position - p).norm() < config_.fuel.min_view_distance) return true;
  }
  return false;
}

double FuelStrategy::remaining_fraction(const PlanContext& ctx, const Target& t) const {
  if (t.voxels.empty()) return 0.0;
  size_t left = 0;
  for (const VoxelKey& k : t.voxels) left += eligible(ctx, k) ? 1 : 0;
  return static_cast<double>(left) / static_cast<double>(t.voxels.size());
}

int64_t FuelStrategy::successor(const Target& t) const {
  std::map<int64_t, int64_t> votes;
  for (const VoxelKey& k : t.voxels) {
    const int64_t id = clusters_.owner(k);
    if (id >= 0) ++votes[id];
  }
  int64_t best = -1, n = 0;
  for (const auto& [id, v] : votes) {
    if (v > n) best = id, n = v;
  }
  return best;
}

double FuelStrategy::site_distance(int a, int b) const {
  const Site& sa = sites_[static_cast<size_t>(a)];
  const Site& sb = sites_[static_cast<size_t>(b)];
  const ClusterState& ca = state_.at(sa.cluster);
  const ClusterState& cb = state_.at(sb.cluster);
  const Eigen::Vector3d& pa = ca.views[static_cast<size_t>(sa.views[static_cast<size_t>(sa.rep)])].position;
  const Eigen::Vector3d& pb = cb.views[static_cast<size_t>(sb.views[static_cast<size_t>(sb.rep)])].position;
  // Either direction's search (path lengths are symmetric), if it was from and to these points.
  if (ca.row_from == pa) {
    const auto it = ca.row.find(sb.cluster);
    if (it != ca.row.end() && it->second.first == pb) return it->second.second;
  }
  if (cb.row_from == pb) {
    const auto it = cb.row.find(sa.cluster);
    if (it != cb.row.end() && it->second.first == pa) return it->second.second;
  }
  // Not searched yet (cost_budget): a lower bound from the straight line and the triangle
  // inequality through the vehicle.
  const double da = sa.vehicle_distance[static_cast<size_t>(sa.rep)];
  const double db = sb.vehicle_distance[static_cast<size_t>(sb.rep)];
  return std::max((pa - pb).norm(), std::abs(da - db));
}

double FuelStrategy::view_distance(int a, int va, int b, int vb) const {
  const Site& sa = sites_[static_cast<size_t>(a)];
  const Site& sb = sites_[static_cast<size_t>(b)];
  const std::vector<Viewpoint>& wa = state_.at(sa.cluster).views;
  const std::vector<Viewpoint>& wb = state_.at(sb.cluster).views;
  const Eigen::Vector3d& pa = wa[static_cast<size_t>(sa.views[static_cast<size_t>(va)])].position;
  const Eigen::Vector3d& pb = wb[static_cast<size_t>(sb.views[static_cast<size_t>(vb)])].position;
  const Eigen::Vector3d& ra = wa[static_cast<size_t>(sa.views[static_cast<size_t>(sa.rep)])].position;
  const Eigen::Vector3d& rb = wb[static_cast<size_t>(sb.views[static_cast<size_t>(sb.rep)])].position;
  // Searching between every pair of the refined viewpoints (FUEL runs an A* per pair) would cost
  // a Dijkstra each; the representatives' distance less the offsets from them is a lower bound
  // that keeps the detours a wall imposes.
  return std::max((pa - pb).norm(), site_distance(a, b) - (pa - ra).norm() - (pb - rb).norm());
}

void FuelStrategy::compute_rows(PlanContext& ctx) {
  // Nearest representatives first: the start of the tour is what is flown.
  std::vector<int> order(sites_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  auto rep_distance = [&](int i) {
    const Site& s = sites_[static_cast<size_t>(i)];
    return s.vehicle_distance[static_cast<size_t>(s.rep)];
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return rep_distance(a) < rep_distance(b); });
  int64_t used = 0;
  std::vector<Eigen::Vector3d> targets;
  for (int i : order) {
    if (used >= config_.fuel.cost_budget) break;
    const Site& s = sites_[static_cast<size_t>(i)];
    ClusterState& cs = state_.at(s.cluster);
    const Eigen::Vector3d from = cs.views[static_cast<size_t>(s.views[static_cast<size_t>(s.rep)])].position;
    // A row is searched once per representative; clusters added later are covered by their own.
    if (cs.row_from == from) continue;
    targets.clear();
    std::vector<int64_t> ids;
    for (size_t j = 0; j < sites_.size(); ++j) {
      if (static_cast<int>(j) == i) continue;
      const Site& t = sites_[j];
      targets.push_back(
          state_.at(t.cluster).views[static_cast<size_t>(t.views[static_cast<size_t>(t.rep)])].position);
      ids.push_back(t.cluster);
    }
    core::Stopwatch w;
    const GridSearch::Result r = search_.distances(from, false, targets, kMaxFieldCells, false);
    ctx.counters->search_ms += w.ms();
    ctx.counters->search_settled += r.settled;
    used += r.settled;
    cs.row_from = from;
    cs.row.clear();
    for (size_t j = 0; j < ids.size(); ++j) cs.row[ids[j]] = {targets[j], r.distance[j]};
  }
}

std::optional<FuelStrategy::Planned> FuelStrategy::plan_tour(PlanContext& ctx, int64_t keep,
                                                             double* keep_cost, std::string* reason,
                                                             int64_t* waiting, const Keeps& keeps) {
  const FuelConfig& f = config_.fuel;
  const CostConfig& cost = config_.cost;
  skipped_until_ = -1;
  bool far_tried = false;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    sites_.clear();
    tour_.clear();
    // Each cluster's top viewpoints that are not blacklisted, and the vehicle's distance to each.
    std::vector<Eigen::Vector3d> targets;
    std::vector<std::pair<int64_t, int>> owner;  // (cluster, view index) per target
    int64_t with_views = 0, banned_only = 0;
    for (const auto& [id, cs] : state_) {
      if (cs.views.empty()) continue;
      ++with_views;
      int taken = 0;
      for (size_t v = 0; v < cs.views.size() && taken < f.top_views; ++v) {
        if (blacklisted(cs.views[v].position, ctx.cycle)) continue;
        targets.push_back(cs.views[v].position);
        owner.emplace_back(id, static_cast<int>(v));
        ++taken;
      }
      if (taken == 0) {
        // Every view of the cluster is banned: it is free again when its first ban ends, and the
        // plan can wait for the first cluster that is.
        ++banned_only;
        int64_t free_at = std::numeric_limits<int64_t>::max();
        for (const Viewpoint& vp : cs.views) free_at = std::min(free_at, ban_end(vp.position, ctx.cycle));
        if (free_at != kForGood)
          skipped_until_ = skipped_until_ < 0 ? free_at : std::min(skipped_until_, free_at);
      }
    }
    core::Stopwatch sw;
    const GridSearch::Result field = search_.distances(vehicle_, true, targets, kMaxFieldCells, true);
    ctx.counters->search_ms += sw.ms();
    ctx.counters->search_settled += field.settled;
    for (size_t t = 0; t < targets.size(); ++t) {
      if (!(field.distance[t] < kInf)) continue;
      if (sites_.empty() || sites_.back().cluster != owner[t].first) {
        Site s;
        s.cluster = owner[t].first;
        sites_.push_back(s);
      }
      sites_.back().views.push_back(owner[t].second);
      sites_.back().vehicle_distance.push_back(field.distance[t]);
    }
    for (Site& s : sites_) {
      // FUEL's getTopViewpointsInfo: the best-covering viewpoint not right at the vehicle.
      s.rep = 0;
      const std::vector<Viewpoint>& views = state_.at(s.cluster).views;
      for (size_t v = 0; v < s.views.size(); ++v) {
        if ((views[static_cast<size_t>(s.views[v])].position - vehicle_).norm() >= f.min_view_distance) {
          s.rep = static_cast<int>(v);
          break;
        }
      }
    }
    // FUEL-size clusters first: the smaller ones only once none of those is left.
    auto major = [&](const Site& s) {
      const FrontierClusters::Cluster* c = clusters_.find(s.cluster);
      return c &&
             ((static_cast<int64_t>(c->voxels.size()) >= f.major_cluster_voxels &&
               state_.at(s.cluster).views[static_cast<size_t>(s.views[0])].coverage >= f.major_coverage) ||
              promoted(ctx, *c));
    };
    const bool any_major = std::any_of(sites_.begin(), sites_.end(), major);
    if (any_major)
      sites_.erase(std::remove_if(sites_.begin(), sites_.end(), [&](const Site& s) { return !major(s); }),
                   sites_.end());
    if (waiting) *waiting = banned_only;
    if (sites_.empty() && f.far_rings && !far_tried) {
      // The last resort before the tour runs dry: clusters of FUEL's size without a viewpoint get
      // rings out to the camera's range. Only then, as a far view is often where the vehicle saw
      // the cluster from, at the edge of its depth range, and seeing it again maps little: on
      // every plan they cost the 24-world set 9 % of Time_r (set 24: 168 -> 348 s). Without them
      // semantic-fuel on the latency tour ended DONE at 53 % in env2's process set (seed 1),
      // with 8 clusters seen through the doorway and none with a viewpoint. For clusters of any
      // size, the small ones left at the end made 10 of the 24 runs longer (Time_f up to +38 s);
      // with FUEL's size as the least, 2. A cluster keeps its far views until it changes.
      far_tried = true;
      int64_t got = 0;
      for (auto& [id, cs] : state_) {
        const FrontierClusters::Cluster* c = clusters_.find(id);
        if (!cs.views.empty() || !c || static_cast<int64_t>(c->voxels.size()) < f.major_cluster_voxels)
          continue;
        const double phase = ctx.rng ? ctx.rng->uniform() : 0.0;
        cs.views = sampler_.sample(*ctx.grid, *c, ctx.counters, phase, true);
        cs.sampled_cycle = ctx.cycle;
        got += cs.views.empty() ? 0 : 1;
      }
      if (got > 0) {
        --attempt;
        continue;
      }
    }
    if (sites_.empty()) {
      std::ostringstream r;
      r << "no frontier cluster with a reachable viewpoint (" << clusters_.clusters().size()
        << " clusters of >= " << f.min_cluster_voxels << " voxels, " << with_views << " with viewpoints, "
        << banned_only << " of them only near goals skipped for now); "
        << (ctx.frontiers ? ctx.frontiers->size() : 0) << " frontier voxels left";
      *reason = r.str();
      return std::nullopt;
    }
    compute_rows(ctx);

    // The global tour (asymmetric: the vehicle's heading, and returns free).
    const int n = static_cast<int>(sites_.size()) + 1;
    TourProblem problem;
    problem.n = n;
    problem.cost.assign(static_cast<size_t>(n) * static_cast<size_t>(n), 0.0);
    auto rep_view = [&](int i) -> const Viewpoint& {
      const Site& s = sites_[static_cast<size_t>(i)];
      return state_.at(s.cluster).views[static_cast<size_t>(s.views[static_cast<size_t>(s.rep)])];
    };
    for (int i = 0; i < n - 1; ++i) {
      const Site& s = sites_[static_cast<size_t>(i)];
      problem.cost[static_cast<size_t>(i + 1)] =
          first_leg(s.vehicle_distance[static_cast<size_t>(s.rep)], rep_view(i).position, rep_view(i).yaw);
      for (int j = 0; j < n - 1; ++j) {
        if (i == j) continue;
        problem.cost[static_cast<size_t>(i + 1) * static_cast<size_t>(n) + static_cast<size_t>(j + 1)] =
            travel_time(site_distance(i, j), rep_view(i).yaw, rep_view(j).yaw, cost);
      }
    }
    {
      std::vector<Eigen::Vector3d> reps, means;
      for (int i = 0; i < n - 1; ++i) {
        reps.push_back(rep_view(i).position);
        means.push_back(clusters_.find(sites_[static_cast<size_t>(i)].cluster)->mean);
      }
      add_tour_costs(ctx, search_, reps, means, problem);
    }
    core::Stopwatch tw;
    // With latency_tour, a tour's cost is its weighted latency (each site weighs what its
    // representative viewpoint covers), found from the shortest tour by local moves; the order
    // that keeps the target keeps it first and orders the rest so.
    std::vector<double> weight;
    if (f.latency_tour) {
      weight.assign(static_cast<size_t>(n), 0.0);
      for (int i = 0; i < n - 1; ++i) {
        double w = rep_view(i).coverage;
        if (f.latency_gain) {
          const NodeGain g = gains_.evaluate(*ctx.grid, rep_view(i).position);
          w = std::pow(gains_.gain_at_yaw(g, rep_view(i).yaw), f.latency_gain_power);
        }
        weight[static_cast<size_t>(i + 1)] =
            latency_weight(ctx, *clusters_.find(sites_[static_cast<size_t>(i)].cluster), w);
      }
    }
    double total_weight = 0.0;
    for (const double w : weight) total_weight += w;
    // The latency tour's cost: the weighted latency, and with latency_quota the time to that share.
    const auto judged = [&](const std::vector<int>& o) {
      double c = latency_cost(problem, o, weight);
      if (f.latency_quota > 0)
        c += f.quota_weight * total_weight * quota_time(problem, o, weight, f.latency_quota);
      return c;
    };
    auto by_latency = [&](Tour t, bool keep_first) {
      if (t.order.size() < 2) {
        t.cost = judged(t.order);
        return t;
      }
      const int head = t.order.front();
      std::vector<int> rest = t.order;
      if (keep_first) rest.erase(rest.begin());
      auto whole = [&](const std::vector<int>& r) {
        if (!keep_first) return r;
        std::vector<int> o{head};
        o.insert(o.end(), r.begin(), r.end());
        return o;
      };
      const auto objective = [&](const std::vector<int>& r) { return judged(whole(r)); };
      rest = improve_order(rest, objective, f.latency_evaluations, false);
      t.order = whole(rest);
      t.cost = judged(t.order);
      return t;
    };
    Tour tour = solve_open_tour(problem, f.exact_tour_max);
    if (f.latency_tour) tour = by_latency(std::move(tour), false);
    if (f.latency_tour && f.rate_first && tour.order.size() > 1) {
      const int best = highest_rate_node(problem, weight);
      Tour t;
      t.order = {best};
      for (int v : tour.order)
        if (v != best) t.order.push_back(v);
      tour = by_latency(std::move(t), true);
    }
    if (keep_cost) {
      *keep_cost = kInf;
      for (int i = 0; i < n - 1; ++i) {
        if (sites_[static_cast<size_t>(i)].cluster != keep) continue;
        Tour k = solve_open_tour(problem, f.exact_tour_max, i + 1);
        *keep_cost = f.latency_tour ? by_latency(std::move(k), true).cost : k.cost;
      }
    }
    for (int v : tour.order) tour_.push_back(sites_[static_cast<size_t>(v - 1)].cluster);

    // Local refinement (FUEL's refineLocalTour): the first clusters of the tour choose among
    // their top viewpoints by a shortest path through the layers, the last one keeps its
    // representative.
    std::vector<int> layer_site;
    for (int v : tour.order) {
      const int s = v - 1;
      layer_site.push_back(s);
      if (static_cast<int>(layer_site.size()) >= f.refine_clusters) break;
      if ((rep_view(s).position - vehicle_).norm() > f.refine_radius && layer_site.size() >= 2) break;
    }
    const size_t layers = layer_site.size();
    std::vector<std::vector<int>> choices(layers);  // indices into the site's views
    for (size_t l = 0; l < layers; ++l) {
      const Site& s = sites_[static_cast<size_t>(layer_site[l])];
      if (l + 1 == layers && layers > 1) {
        choices[l] = {s.rep};
        continue;
      }
      const std::vector<Viewpoint>& views = state_.at(s.cluster).views;
      const double floor_coverage = f.max_decay * views[static_cast<size_t>(s.views[0])].coverage;
      for (int pass = 0; pass < 2 && choices[l].empty(); ++pass) {
        for (size_t v = 0; v < s.views.size(); ++v) {
          const Viewpoint& vp = views[static_cast<size_t>(s.views[v])];
          if (v > 0 && vp.coverage <= floor_coverage) break;
          // First pass: not right at the vehicle; then any (FUEL's getViewpointsInfo).
          if (pass == 0 && (vp.position - vehicle_).norm() < f.min_view_distance) continue;
          choices[l].push_back(static_cast<int>(v));
        }
      }
    }
    std::vector<std::vector<double>> best(layers);
    std::vector<std::vector<int>> from(layers);
    for (size_t l = 0; l < layers; ++l) {
      const Site& s = sites_[static_cast<size_t>(layer_site[l])];
      const std::vector<Viewpoint>& views = state_.at(s.cluster).views;
      best[l].assign(choices[l].size(), kInf);
      from[l].assign(choices[l].size(), -1);
      for (size_t c = 0; c < choices[l].size(); ++c) {
        const Viewpoint& vp = views[static_cast<size_t>(s.views[static_cast<size_t>(choices[l][c])])];
        if (l == 0) {
          best[0][c] = first_leg(s.vehicle_distance[static_cast<size_t>(choices[0][c])], vp.position, vp.yaw);
          continue;
        }
        const Site& ps = sites_[static_cast<size_t>(layer_site[l - 1])];
        const std::vector<Viewpoint>& pviews = state_.at(ps.cluster).views;
        for (size_t u = 0; u < choices[l - 1].size(); ++u) {
          const Viewpoint& up = pviews[static_cast<size_t>(ps.views[static_cast<size_t>(choices[l - 1][u])])];
          const double d = view_distance(layer_site[l - 1], choices[l - 1][u], layer_site[l], choices[l][c]);
          const double c2 = best[l - 1][u] + travel_time(d, up.yaw, vp.yaw, cost);
          if (c2 < best[l][c]) best[l][c] = c2, from[l][c] = static_cast<int>(u);
        }
      }
    }
    int pick = 0;
    for (size_t c = 1; c < best[layers - 1].size(); ++c)
      if (best[layers - 1][c] < best[layers - 1][static_cast<size_t>(pick)]) pick = static_cast<int>(c);
    for (size_t l = layers - 1; l > 0; --l) pick = from[l][static_cast<size_t>(pick)];
    ctx.counters->search_ms += tw.ms();

    const Site& first = sites_[static_cast<size_t>(layer_site[0])];
    const int view_index = first.views[static_cast<size_t>(choices[0][static_cast<size_t>(pick)])];
    const Viewpoint goal_view = state_.at(first.cluster).views[static_cast<size_t>(view_index)];
    const double goal_distance =
        first.vehicle_distance[static_cast<size_t>(choices[0][static_cast<size_t>(pick)])];

    Planned p;
    p.minor_only = !any_major;
    p.cluster = first.cluster;
    p.site = layer_site[0];
    p.tour_cost = tour.cost;
    Goal& g = p.goal;
    g.valid = true;
    g.node = first.cluster + 1;  // node ids of the roadmap view: 0 is the vehicle
    g.position = goal_view.position;
    g.yaw = goal_view.yaw;
    g.gain = goal_view.coverage;
    g.cost = travel_time(goal_distance, vehicle_yaw_, goal_view.yaw, cost);
    g.score = g.gain / g.cost;
    // A plan that keeps the target flies the path already flown: its own search would be thrown
    // away, and in the 600 m² world such searches of 10-18 ms were 7 of semantic-fuel's 40
    // largest cycles (issue 33). Its view's reachability is asked when it is chosen to be flown.
    if (keeps && keeps(p, keep_cost ? *keep_cost : kInf)) return p;

    // The path: A* over voxels along the coarse path, then anywhere.
    core::Stopwatch pw;
    std::vector<Eigen::Vector3d> waypoints;
    int64_t expanded = 0;
    const std::vector<Eigen::Vector3d> guide = search_.tree_path(goal_view.position);
    bool found = search_.find_path(vehicle_, goal_view.position, guide, kMaxPathVoxels, waypoints, &expanded);
    ctx.counters->search_settled += expanded;
    ++ctx.counters->paths_searched;
    if (!found && !guide.empty()) {
      found = search_.find_path(vehicle_, goal_view.position, {}, kMaxDetourVoxels, waypoints, &expanded);
      ctx.counters->search_settled += expanded;
      ++ctx.counters->paths_searched;
    }
    if (!found && config_.fuel.approach && guide.size() >= 2 &&
        ++count_at(approaches_, goal_view.position, config_.fuel.min_view_distance) <= kApproaches) {
      // The coarse lattice is lenient where A* keeps the passage clearance (below): a doorway
      // the map knows only part of, seen from afar or through itself, passes on one and not on
      // the other. Flying as far along the coarse path as A* reaches, looking along it, brings
      // the doorway into view, and the next plan finds the way or not. Without it semantic-fuel
      // ended DONE at 55.6 % in env2's process set (the latency tour, seed 9): every view of the
      // far room struck off from the first room, which the vehicle had not left.
      double yaw = goal_view.yaw;
      if (approach(guide, ctx.counters, waypoints, yaw)) {
        g.position = waypoints.back();
        g.yaw = yaw;
        g.cost = travel_time(path_length(waypoints), vehicle_yaw_, yaw, cost);
        g.score = g.gain / g.cost;
        found = true;
      }
    }
    ctx.counters->connect_ms += pw.ms();
    if (!found) {
      // The field's lattice is lenient (grid_search.hpp) where A* keeps the passage clearance,
      // so a view can be reached on one and never on the other. While recovering nothing else is
      // flown and the map stands still, so its search fails again when the skip ends: env3 with
      // noise (fuel, seed 2, mapper without held voxels) skipped and freed three clusters' views
      // every 21 cycles from 198 s to the 900 s limit, each skip holding DONE back. A view whose
      // search failed while recovering is a strike at its place, as a visit is (reject_goal).
      int64_t until = ctx.cycle + config_.loop.blacklist_cycles;
      if (ctx.recovering &&
          ++count_at(strikes_, goal_view.position, config_.fuel.min_view_distance) >= kStrikes)
        until = kForGood;
      blacklist_.push_back({goal_view.position, until});
      *reason = "no path to the tour's next viewpoint";
      continue;
    }
    // 9 m: under the controller's 10 m with room for its rounding (env3 with sensor noise: 57
    // paths of 11.7-11.9 m segments rejected in 2.5 s bursts, each goal skipped after).
    g.waypoints = split_long_segments(waypoints, 9.0);
    g.yaws = turn_early_yaws(g.waypoints, vehicle_yaw_, g.yaw, cost.velocity, cost.yaw_rate);
    square_near_obstacles(g.waypoints, g.yaws);
    return p;
  }
  return std::nullopt;
}

bool FuelStrategy::approach(const std::vector<Eigen::Vector3d>& guide, CycleCounters* counters,
                            std::vector<Eigen::Vector3d>& out, double& yaw) {
  // Ends tried from the view back toward the vehicle, every 0.6 m of the guide; each search only
  // in the corridor of the guide up to its end, so a few tries cost about one search.
  constexpr double kStep = 0.6, kLeast = 1.0;
  constexpr int kTries = 6;
  constexpr int64_t kBudget = 60000;
  std::vector<double> arc(guide.size(), 0.0);
  for (size_t i = 1; i < guide.size(); ++i) arc[i] = arc[i - 1] + (guide[i] - guide[i - 1]).norm();
  double next = arc.back() - kStep;
  int tries = 0;
  for (size_t i = guide.size() - 1; i > 0 && tries < kTries; --i) {
    if (arc[i] > next || arc[i] < kLeast) continue;
    next = arc[i] - kStep;
    if (!checker_.node_free(guide[i])) continue;
    ++tries;
    const std::vector<Eigen::Vector3d> prefix(guide.begin(),
                                              guide.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    int64_t expanded = 0;
    std::vector<Eigen::Vector3d> path;
    const bool found = search_.find_path(vehicle_, guide[i], prefix, kBudget, path, &expanded);
    if (counters) {
      counters->search_settled += expanded;
      ++counters->paths_searched;
    }
    if (!found || path.size() < 2) continue;
    const Eigen::Vector3d along = guide[i + 1] - guide[i];
    if (along.head<2>().norm() > 1e-6) yaw = std::atan2(along.y(), along.x());
    out = std::move(path);
    return true;
  }
  return false;
}

void FuelStrategy::square_near_obstacles(const std::vector<Eigen::Vector3d>& w,
                                         std::vector<double>& yaws) const {
  const double c = config_.fuel.square_clearance;
  if (!(c > 0.0)) return;
  // The first waypoint is the vehicle and the last the view, whose yaw is what the path is for.
  for (size_t i = 1; i + 1 < w.size() && i + 1 < yaws.size(); ++i) {
    if (checker_.esdf(w[i], c) >= c) continue;
    const Eigen::Vector3d d = w[i + 1] - w[i - 1];
    if (d.head<2>().norm() < 1e-6) continue;
    yaws[i] = std::atan2(d.y(), d.x());
  }
}

PlanOutcome FuelStrategy::plan(PlanContext& ctx) {
  checker_.set_grid(ctx.grid);
  search_.set_grid(ctx.grid);
  gains_.set_ignored(ctx.unobservable);
  checker_.reset_counters();
  if (last_utime_ >= 0 && ctx.pose.utime > last_utime_) {
    const double dt = 1e-6 * static_cast<double>(ctx.pose.utime - last_utime_);
    velocity_ = (ctx.pose.position - last_position_) / dt;
    yaw_speed_ = core::wrap_angle(ctx.pose.yaw - last_yaw_) / dt;
  }
  last_position_ = ctx.pose.position;
  last_yaw_ = ctx.pose.yaw;
  last_utime_ = ctx.pose.utime;
  // FUEL replans from where the vehicle will be on its trajectory when the new one starts
  // (FastExplorationFSM: replan_time ahead), not from where it is: a path from the pose of the
  // cycle sends the vehicle back to it once released (the least charge later), and the closed
  // loop turned back to the old heading at every replan (env1: 0.4 rad/s of the 1 rad/s turn).
  vehicle_ = ctx.pose.position;
  vehicle_yaw_ = ctx.pose.yaw;
  const double lead = config_.charge.scale * config_.charge.min_s;
  if (lead > 0 && velocity_.norm() > 1e-3) {
    const Eigen::Vector3d v = velocity_.norm() > config_.cost.velocity
                                  ? Eigen::Vector3d(velocity_.normalized() * config_.cost.velocity)
                                  : velocity_;
    const Eigen::Vector3d ahead = ctx.pose.position + lead * v;
    checker_.set_grid(ctx.grid);
    if (ctx.grid->state(ahead) == map::VoxelState::kFree && checker_.edge_free(ctx.pose.position, ahead))
      vehicle_ = ahead;
  }
  vehicle_yaw_ = core::wrap_angle(
      ctx.pose.yaw + lead * std::clamp(yaw_speed_, -config_.cost.yaw_rate, config_.cost.yaw_rate));
  {
    core::Stopwatch w;
    update_clusters(ctx);
    ctx.counters->sample_ms += w.ms();
  }
  cycle_ = ctx.cycle;
  blacklist_.erase(std::remove_if(blacklist_.begin(), blacklist_.end(),
                                  [&](const Banned& b) { return b.until_cycle < ctx.cycle; }),
                   blacklist_.end());
  switch_ = false;
  replan_reason_.clear();
  PlanOutcome out;
  auto finish = [&]() {
    ctx.counters->box_checks += checker_.box_checks();
    checker_.reset_counters();
    return out;
  };

  if (look_.valid && !ctx.need_goal) {  // a turn in place is flown to its end
    out.goal = look_;
    return finish();
  }
  look_ = Goal();

  // FUEL's FSM: plan again when a goal is needed, the target is covered, or periodically.
  const FuelConfig& f = config_.fuel;
  std::string why;
  bool periodic = false;
  if (ctx.need_goal || !target_.valid) {
    why = ctx.need_goal ? "goal needed" : "no target";
  } else if (!target_.committed && remaining_fraction(ctx, target_) < 1.0 - f.covered_fraction) {
    // (A committed target, given_up_, is flown until reached or its view is no longer free.)
    why = "target covered";
  } else if (!checker_.node_free(target_.goal.position)) {
    why = "target viewpoint no longer free";
  } else if (!target_.committed && f.replan_period > 0 &&
             ctx.pose.utime - target_.planned_utime >=
                 static_cast<int64_t>(std::llround(f.replan_period * 1e6))) {
    why = "periodic";
    periodic = true;
  }
  if (why.empty()) {
    out.goal = target_.goal;
    return finish();
  }
  replan_reason_ = why;
  const int64_t keep = periodic ? successor(target_) : -1;
  // Keep the target unless the new tour is clearly cheaper than the best one that keeps it.
  const auto kept_by_period = [&](const Planned& q, double keep_cost) {
    return periodic &&
           !(q.cluster != keep && (!(keep_cost < kInf) || q.tour_cost < (1.0 - f.switch_margin) * keep_cost));
  };
  const auto same_view = [&](const Planned& q) {
    return !ctx.need_goal && target_.valid && q.cluster == target_.cluster &&
           (q.goal.position - target_.goal.position).norm() < kSameView &&
           std::abs(core::wrap_angle(q.goal.yaw - target_.goal.yaw)) < kSameView;
  };
  double keep_cost = kInf;
  std::string reason;
  int64_t waiting = 0;
  const std::optional<Planned> p =
      plan_tour(ctx, keep, periodic ? &keep_cost : nullptr, &reason, &waiting,
                [&](const Planned& q, double c) { return kept_by_period(q, c) || same_view(q); });
  if (periodic) {
    target_.planned_utime = ctx.pose.utime;
    if (!p || kept_by_period(*p, keep_cost)) {
      replan_reason_ = "periodic: kept the target";
      out.goal = target_.goal;
      return finish();
    }
  }
  if (p && same_view(*p)) {
    // The same view chosen again: the path being flown stays. A target whose cluster still
    // counted as covered was replanned every cycle, and each new path restarted the
    // controller's trajectory: env3's process set crawled at 0.8 m/s for 55 s (one goal of gain
    // 25 sent 40 times), while the closed loop's ideal vehicle did not show it.
    target_.voxels = clusters_.find(p->cluster)->voxels;
    target_.planned_utime = ctx.pose.utime;
    replan_reason_ += ": the same view";
    out.goal = target_.goal;
    return finish();
  }
  switch_ = true;
  if (!p) {
    target_ = Target();
    if (!toured_ && looks_ < kLookTurns && (!state_.empty() || ctx.grid->free_voxels() == 0)) {
      // The vehicle has not left its start, and there are clusters, none with a free viewpoint
      // yet, or it has seen nothing at all (a wall nearer than the camera's least depth).
      ++looks_;
      look_ = turn_in_place(ctx.pose.position, ctx.pose.yaw, 0.5 * core::kPi, config_.cost.yaw_rate);
      out.goal = look_;
      out.reason = "turning in place at the start: " + reason;
      return finish();
    }
    out.reason = reason;
    out.unreachable_informative = waiting;
    out.skipped_until = skipped_until_;
    return finish();
  }
  toured_ = true;
  const double near = config_.fuel.min_view_distance;
  if (target_.valid && (vehicle_ - target_.goal.position).norm() >= near)
    ++count_at(given_up_, target_.goal.position, near);
  const auto it = place_at(given_up_, p->goal.position, near);
  target_.committed = p->minor_only && it != given_up_.end() && it->second >= kCommit;
  target_.valid = true;
  target_.cluster = p->cluster;
  target_.voxels = clusters_.find(p->cluster)->voxels;
  target_.planned_utime = ctx.pose.utime;
  target_.goal = p->goal;
  out.goal = p->goal;
  return finish();
}

std::optional<double> FuelStrategy::goal_score(PlanContext&, const Goal& goal) {
  // A replan that chose another goal supersedes the one being flown.
  if (switch_) return std::nullopt;
  return goal.score;
}

void FuelStrategy::reject_goal(const Goal& goal, int64_t until_cycle) {
  // Reached again and again without its cluster going: a view that only counts voxels it cannot
  // see had a vehicle fly to it, wait out the skip and fly to it again until the time limit (a
  // 140 m² world, the process set, 100 s at 99.8 %). A strike is a visit (the vehicle is there; a
  // goal given up for a better one or refused by the controller is not) after the place's skip
  // ended: places skipped together are one.
  const double near = config_.fuel.min_view_distance;
  if ((vehicle_ - goal.position).norm() < near && !blacklisted(goal.position, cycle_)) {
    if (++count_at(strikes_, goal.position, near) >= kStrikes) until_cycle = kForGood;
  }
  blacklist_.push_back({goal.position, until_cycle});
  if (target_.valid && (target_.goal.position - goal.position).norm() < 1e-9) target_.valid = false;
}

RoadmapView FuelStrategy::roadmap(const Goal* goal) const {
  RoadmapView v;
  RoadmapView::Node root;
  root.id = 0;
  root.position = vehicle_;
  root.yaw = vehicle_yaw_;
  root.cost = 0.0;
  root.flags = kFlagRoot;
  v.nodes.push_back(root);
  for (const Site& s : sites_) {
    const auto it = state_.find(s.cluster);
    if (it == state_.end() || s.rep < 0) continue;
    const Viewpoint& vp = it->second.views[static_cast<size_t>(s.views[static_cast<size_t>(s.rep)])];
    RoadmapView::Node n;
    n.id = s.cluster + 1;
    n.position = vp.position;
    n.yaw = vp.yaw;
    n.gain = vp.coverage;
    n.cost = travel_time(s.vehicle_distance[static_cast<size_t>(s.rep)], vehicle_yaw_, vp.yaw, config_.cost);
    n.score = n.gain / n.cost;
    n.flags = kFlagFrontier;
    if (goal && goal->valid && goal->node == n.id) n.flags |= kFlagGoal | kFlagOnPath;
    v.nodes.push_back(n);
  }
  // The tour as edges from the vehicle.
  int64_t prev = 0;
  for (int64_t c : tour_) {
    v.edges.emplace_back(prev, c + 1);
    prev = c + 1;
  }
  return v;
}

}  // namespace semx::planner
