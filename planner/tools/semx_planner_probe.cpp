// semx-planner-probe: what the planner's collision checks say about doorways on a real map (a
// run folder's map.bt, or semx-map-replay's of a log; the planner reads the map's states alone,
// which is all a .bt keeps, so the probe needs nothing of the mapper). For each doorway it
// prints horizontal slices of the voxel states with the points where a roadmap node may stand,
// and how many straight edges through the doorway pass the edge check. Debugging aid for
// "the roadmap never connects this room" (docs/planner.md, "Narrow passages").
//
//   semx-planner-probe map.bt [--door X,Y,AXIS]... [--edge ...]... [--set KEY=VALUE]...
//
// AXIS is the axis the wall runs along (x: a wall of constant y, crossed along y). Without
// --door, env3's doorways.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "semx/core/random.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/frontier_tracker.hpp"
#include "semx/planner/fuel_strategy.hpp"
#include "semx/planner/grid_search.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

using namespace semx;

namespace {

// A run folder's map.bt (the evaluator's copy of the map: each known voxel at the clamping
// log-odds of its state) as voxel states.
void load_bt(const std::string& path, map::StateGrid& grid) {
  octomap::OcTree tree(0.1);
  if (!tree.readBinary(path)) throw runtime::ConfigError(path + ": not an OctoMap binary tree");
  const double res = tree.getResolution();
  if (std::abs(res - grid.resolution()) > 1e-9)
    throw runtime::ConfigError(path + ": resolution " + std::to_string(res) +
                               ", the planner's map has 0.1 m");
  const map::KeyMath km(res);
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const map::VoxelState s = tree.isNodeOccupied(*it) ? map::VoxelState::kOccupied : map::VoxelState::kFree;
    const int n = static_cast<int>(std::lround(it.getSize() / res));  // a pruned leaf spans n^3 voxels
    const octomap::point3d c = it.getCoordinate();
    const Eigen::Vector3d lo(c.x() - 0.5 * it.getSize() + 0.5 * res, c.y() - 0.5 * it.getSize() + 0.5 * res,
                             c.z() - 0.5 * it.getSize() + 0.5 * res);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          map::VoxelKey k;
          if (km.key(lo + Eigen::Vector3d(x, y, z) * res, k)) grid.set_state(k, s);
        }
  }
}

struct Door {
  double x, y;
  char axis;  // 'x': the wall runs along x (constant y), the doorway is crossed along y
};

Eigen::Vector3d at(const Door& d, double along, double across, double z) {
  return d.axis == 'x' ? Eigen::Vector3d(d.x + along, d.y + across, z)
                       : Eigen::Vector3d(d.x + across, d.y + along, z);
}

// "X,Y,Z" from `in`, and a separator after it when `more`.
bool read_point(std::istream& in, Eigen::Vector3d& a, bool more) {
  char c;
  if (!(in >> a.x() >> c >> a.y() >> c >> a.z())) return false;
  return !more || static_cast<bool>(in >> c);
}

// "X,Y,Z" (--fuel).
bool parse_point(const std::string& s, Eigen::Vector3d& a) {
  std::istringstream in(s);
  return read_point(in, a, false);
}

// One FUEL-family plan from `at` on the map, as the planner's first cycle on it would make it
// (fresh clusters, no blacklist): its goal or why there is none, then every frontier cluster
// with its viewpoints. Answers "why did FUEL find nothing to fly to here".
void probe_fuel(const map::StateGrid& grid, const planner::PlannerConfig& config, const Eigen::Vector3d& at) {
  planner::FrontierTracker frontiers(1.0);
  frontiers.reset(grid);
  planner::FuelStrategy fuel(config);
  core::SplitMixRng rng(config.seed);
  planner::CycleCounters counters;
  std::vector<planner::SemanticRegion> regions;
  planner::PlanContext ctx;
  ctx.grid = &grid;
  ctx.pose.position = at;
  ctx.regions = &regions;
  ctx.frontiers = &frontiers;
  ctx.cycle = 1;
  ctx.rng = &rng;
  ctx.counters = &counters;
  ctx.need_goal = true;
  const planner::PlanOutcome o = fuel.plan(ctx);
  std::printf("fuel from (%.2f %.2f %.2f): %zu frontier voxels, %zu clusters\n", at.x(), at.y(), at.z(),
              frontiers.size(), fuel.clusters().clusters().size());
  if (o.goal.valid)
    std::printf("goal (%.2f %.2f %.2f) yaw %.2f, %zu waypoints\n", o.goal.position.x(), o.goal.position.y(),
                o.goal.position.z(), o.goal.yaw, o.goal.waypoints.size());
  else
    std::printf("no goal: %s\n", o.reason.c_str());
  for (const auto& [id, c] : fuel.clusters().clusters()) {
    const std::vector<planner::Viewpoint>& views = fuel.viewpoints(id);
    std::printf("  cluster %lld: %zu voxels, mean (%.2f %.2f %.2f), %zu viewpoints",
                static_cast<long long>(id), c.voxels.size(), c.mean.x(), c.mean.y(), c.mean.z(),
                views.size());
    if (!views.empty())
      std::printf(", best (%.2f %.2f %.2f) covers %.0f", views.front().position.x(),
                  views.front().position.y(), views.front().position.z(), views.front().coverage);
    std::printf("\n");
  }
}

// "AX,AY,AZ,BX,BY,BZ" (--edge, --path).
bool parse_points(const std::string& s, Eigen::Vector3d& a, Eigen::Vector3d& b) {
  std::istringstream in(s);
  return read_point(in, a, true) && read_point(in, b, false);
}

void probe(const map::StateGrid& grid, const planner::CollisionChecker& checker, const Door& d) {
  const double res = grid.resolution();
  std::printf("== doorway (%.2f, %.2f) wall along %c\n", d.x, d.y, d.axis);
  for (double z : {0.75, 1.05, 1.35, 1.65}) {
    std::printf(" z=%.2f   rows: across (wall normal) -1.0..+1.0; columns: along -0.9..+0.9\n", z);
    for (double across = -1.0 + 0.5 * res; across < 1.0; across += res) {
      std::string row = "  ";
      for (double along = -0.9 + 0.5 * res; along < 0.9; along += res) {
        const Eigen::Vector3d p = at(d, along, across, z);
        const map::VoxelState s = grid.state(p);
        char c = s == map::VoxelState::kOccupied ? '#' : s == map::VoxelState::kUnknown ? '?' : '.';
        if (c == '.' && checker.node_free(p)) c = '+';
        row += c;
      }
      std::printf("%s\n", row.c_str());
    }
  }
  // The gap in the wall plane: per height, the widest free opening, and the largest distance from
  // a point of the doorway plane to the nearest occupied voxel centre (what the ESDF measures)
  // and to the nearest occupied-or-unknown voxel cube (what the planner measures).
  for (double z = 0.55; z < 1.8; z += 0.2) {
    double best_esdf = 0, best_cube = 0;
    for (double along = -0.6; along <= 0.6; along += 0.01) {
      const Eigen::Vector3d q = at(d, along, 0.0, z);
      const map::VoxelKey k = grid.keys().key(q);
      double esdf = 1e9, cube = 1e9;
      for (int dz = -8; dz <= 8; ++dz)
        for (int dy = -8; dy <= 8; ++dy)
          for (int dx = -8; dx <= 8; ++dx) {
            const map::VoxelKey v{k.x + dx, k.y + dy, k.z + dz};
            const map::VoxelState s = grid.state(v);
            if (s == map::VoxelState::kFree) continue;
            const Eigen::Vector3d lo(v.x * res, v.y * res, v.z * res);
            const Eigen::Vector3d c = q.cwiseMax(lo).cwiseMin(lo + Eigen::Vector3d::Constant(res));
            cube = std::min(cube, (q - c).norm());
            if (s == map::VoxelState::kOccupied)
              esdf = std::min(esdf, (q - lo - Eigen::Vector3d::Constant(0.5 * res)).norm());
          }
      best_esdf = std::max(best_esdf, esdf);
      best_cube = std::max(best_cube, cube);
    }
    std::printf("  z %.2f: max centre distance to occupied %.3f, max cube distance to non-free %.3f\n", z,
                best_esdf, best_cube);
  }
  // Straight crossings: node-free points in the doorway plane, and edges 1.2 m to either side.
  int node_ok = 0, edge_ok = 0, vehicle_ok = 0, tried = 0;
  double best_along = 0, best_z = 0;
  for (double z = 0.4; z <= 1.8; z += 0.05) {
    for (double along = -0.6; along <= 0.6; along += 0.02) {
      ++tried;
      const Eigen::Vector3d p = at(d, along, 0.0, z);
      vehicle_ok += checker.vehicle_free(p);
      if (checker.node_free(p)) ++node_ok;
      if (checker.edge_free(at(d, along, -0.8, z), at(d, along, 0.8, z))) {
        if (edge_ok == 0) best_along = along, best_z = z;
        ++edge_ok;
      }
    }
  }
  std::printf(" crossings tried %d: vehicle box free %d, node_free in the plane %d, edge_free %d", tried,
              vehicle_ok, node_ok, edge_ok);
  if (edge_ok) std::printf(" (first at along %.2f z %.2f)", best_along, best_z);
  std::printf("\n");
  // Why the straight edge through the middle of the free gap fails: the first failing sample and
  // the voxels that block it.
  for (double z : {1.0, 1.3}) {
    for (double along : {-0.05, 0.0, 0.05, 0.1}) {
      const Eigen::Vector3d a = at(d, along, -0.8, z), b = at(d, along, 0.8, z);
      if (checker.edge_free(a, b)) {
        std::printf("  edge along %.2f z %.2f: free\n", along, z);
        continue;
      }
      for (double t = 0; t <= 1.0; t += 0.01) {
        const Eigen::Vector3d q = a + t * (b - a);
        if (checker.node_free(q)) continue;
        std::printf("  edge along %.2f z %.2f: first blocked at (%.2f %.2f %.2f) by", along, z, q.x(), q.y(),
                    q.z());
        const map::KeyMath& km = grid.keys();
        const map::VoxelKey k = km.key(q);
        double best = 1e9;
        for (int dz = -6; dz <= 6; ++dz)
          for (int dy = -6; dy <= 6; ++dy)
            for (int dx = -6; dx <= 6; ++dx) {
              const map::VoxelKey v{k.x + dx, k.y + dy, k.z + dz};
              const map::VoxelState s = grid.state(v);
              if (s == map::VoxelState::kFree) continue;
              const Eigen::Vector3d lo(v.x * res, v.y * res, v.z * res);
              const Eigen::Vector3d c = q.cwiseMax(lo).cwiseMin(lo + Eigen::Vector3d::Constant(res));
              const double dist = (q - c).norm();
              best = std::min(best, dist);
              if (dist < 0.40)
                std::printf(" %s(%.2f %.2f %.2f d%.2f)", s == map::VoxelState::kOccupied ? "occ" : "unk",
                            lo.x() + 0.05, lo.y() + 0.05, lo.z() + 0.05, dist);
            }
        std::printf("\n");
        break;
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return runtime::run_main("semx-planner-probe", [&] {
    std::string map_file, config_file;
    std::vector<std::string> doors, overrides, edges, paths, fuels;
    runtime::ArgParser p("semx-planner-probe",
                         "Prints the planner's collision checks around doorways of a run's map.bt.");
    p.positional("MAP", "an OctoMap .bt (a run folder's map.bt, or semx-map-replay's)", &map_file)
        .option("config", "FILE", "planner YAML", &config_file)
        .repeated("set", "KEY=VALUE", "override one planner config key", &overrides)
        .repeated("door", "X,Y,AXIS", "a doorway: centre and the axis its wall runs along", &doors)
        .repeated("edge", "AX,AY,AZ,BX,BY,BZ", "one edge: what each check says about it and its ends", &edges)
        .repeated("path", "AX,AY,AZ,BX,BY,BZ",
                  "FUEL's grid search from A to B: the coarse distance and the path", &paths)
        .repeated(
            "fuel", "X,Y,Z",
            "one FUEL-family plan from the vehicle at X,Y,Z: its goal, every cluster and its viewpoints",
            &fuels);
    if (!p.parse(argc, argv)) return 0;
    const auto config = runtime::load_config<planner::PlannerConfig>(config_file, overrides);
    map::StateGrid grid(0.1);
    load_bt(map_file, grid);
    planner::CollisionChecker checker(config.collision);
    checker.set_grid(&grid);
    std::vector<Door> list;
    for (const std::string& s : doors) {
      Door d{};
      std::istringstream in(s);
      char c1, c2;
      if (!(in >> d.x >> c1 >> d.y >> c2 >> d.axis)) {
        std::cerr << "bad --door " << s << "\n";
        return 2;
      }
      list.push_back(d);
    }
    for (const std::string& s : edges) {
      Eigen::Vector3d a, b;
      if (!parse_points(s, a, b)) {
        std::cerr << "bad --edge " << s << "\n";
        return 2;
      }
      const auto state = [&](const Eigen::Vector3d& q) {
        const map::VoxelState v = grid.state(q);
        return v == map::VoxelState::kFree       ? "free"
               : v == map::VoxelState::kOccupied ? "occupied"
                                                 : "unknown";
      };
      for (const Eigen::Vector3d& q : {a, b})
        std::printf("point (%.2f %.2f %.2f): %s, node_free %d, passage_free %d, vehicle_free %d, esdf %.3f\n",
                    q.x(), q.y(), q.z(), state(q), checker.node_free(q), checker.passage_free(q),
                    checker.vehicle_free(q), checker.esdf(q, 1.0));
      std::printf("edge: edge_free %d, root_edge_free %d\n", checker.edge_free(a, b),
                  checker.root_edge_free(a, b));
    }
    for (const std::string& s : paths) {
      Eigen::Vector3d a, b;
      if (!parse_points(s, a, b)) {
        std::cerr << "bad --path " << s << "\n";
        return 2;
      }
      // The searches FuelStrategy::plan_tour makes: the coarse field from the vehicle (its escape
      // rule on), then A* along its path, then anywhere.
      planner::GridSearch search(checker, config.collision, config.fuel.search_step, config.fuel.low_clearance_penalty);
      search.set_grid(&grid);
      const planner::GridSearch::Result field = search.distances(a, true, {b}, 4000000, true);
      std::printf("path: coarse distance %.2f m (%lld cells settled)\n", field.distance[0],
                  static_cast<long long>(field.settled));
      std::vector<Eigen::Vector3d> out;
      int64_t expanded = 0;
      const std::vector<Eigen::Vector3d> guide = search.tree_path(b);
      bool found = search.find_path(a, b, guide, 200000, out, &expanded);
      std::printf("path: along the coarse path (%zu points): %s, %lld voxels expanded\n", guide.size(),
                  found ? "found" : "none", static_cast<long long>(expanded));
      if (!found) {
        expanded = 0;
        found = search.find_path(a, b, {}, 200000, out, &expanded);
        std::printf("path: anywhere: %s, %lld voxels expanded\n", found ? "found" : "none",
                    static_cast<long long>(expanded));
      }
      for (const Eigen::Vector3d& q : out) std::printf("  (%.2f %.2f %.2f)\n", q.x(), q.y(), q.z());
    }
    for (const std::string& s : fuels) {
      Eigen::Vector3d a;
      if (!parse_point(s, a)) {
        std::cerr << "bad --fuel " << s << "\n";
        return 2;
      }
      probe_fuel(grid, config, a);
    }
    if ((!edges.empty() || !paths.empty() || !fuels.empty()) && list.empty()) return 0;
    if (list.empty()) {
      list = {{3.5, 5.5, 'x'}, {9.0, 5.5, 'x'}, {12.25, 5.5, 'x'}, {14.75, 5.5, 'x'},
              {2.5, 7.0, 'x'}, {7.7, 7.0, 'x'}, {12.5, 7.0, 'x'},  {7.0, 2.0, 'y'}};
    }
    for (const Door& d : list) probe(grid, checker, d);
    return 0;
  });
}
