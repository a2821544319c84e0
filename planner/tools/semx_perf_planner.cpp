// semx-perf-planner: planning-cycle time over whole explorations of synthetic worlds (the
// ExplorationSim closed loop: ideal vehicle, camera model, no processes), one `name: value unit`
// line per figure (./semx perf planner).
//
//   semx-perf-planner [--world apartment|two_rooms|env1|env2|env3|FILE] [--planner NAME] [--samples N]
//                     [--seed N] [--runs N] [--max-time S] [--set KEY=VALUE]... [--fit] [--verbose]
//                     [--kernels] [--semantics] [--semantics-config FILE] [--time-split] [--out DIR]
//
// env1-3 (the simulator's shipped worlds, voxelised by its ground truth) need the simulator
// library at build time. --fit prints the least-squares charge coefficients of the cycle's wall
// time against the work counters (docs/planner.md, "Planning time"). --kernels times the cycle's
// two hot kernels on the first run's final map (stop it early with --max-time for a map with
// frontiers): a gain evaluation, and ESDF reads along edges with the chunked cache against one
// cube search per voxel centre. --semantics emulates the semantics module with its class table
// (every object of the world a region of its class's weight and radius once a voxel of it is
// known; inactive once half its surface is). --time-split prints where each run's time went
// (core/time_split.hpp, on the evaluator's target set T). --out DIR writes each run's folder as
// the evaluator does (DIR/runs/WORLD-PLANNER-sSAMPLES-seedN/: metrics.json, coverage.csv,
// time_split.json, ...; the figures on T, "source": "closed-loop"), so semx-bench-report DIR
// compares planners seed by seed.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/core/time_split.hpp"
#include "semx/fixtures/exploration_sim.hpp"
#include "semx/fixtures/synthetic_truth.hpp"
#include "semx/fixtures/synthetic_world.hpp"
#include "semx/planner/charge_model.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/exploration_planner.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/oracle_strategy.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

#ifdef SEMX_PERF_WITH_SIMULATOR
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"
#endif
#ifdef SEMX_PERF_WITH_EVALUATOR
#include "semx/evaluator/run_folder.hpp"
#include "semx/evaluator/time_split_picture.hpp"
#endif
#ifdef SEMX_PERF_WITH_SEMANTICS
#include "semx/semantics/config.hpp"
#include "semx/semantics/regions.hpp"
#endif

using namespace semx::planner;
using namespace semx::runtime;
namespace map = semx::map;

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * (static_cast<double>(v.size()) - 1);
  const size_t i = static_cast<size_t>(std::floor(pos));
  const size_t j = std::min(v.size() - 1, i + 1);
  return v[i] + (pos - static_cast<double>(i)) * (v[j] - v[i]);
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The kernels on one map, at points drawn from its free voxels (fixed seed).
void time_kernels(const map::StateGrid& grid, const PlannerConfig& config) {
  semx::core::SplitMixRng rng(1);
  const map::KeyBox box = grid.known_bounds();
  const double res = grid.resolution();
  std::vector<Eigen::Vector3d> points;
  for (int tries = 0; tries < 200000 && points.size() < 400; ++tries) {
    const Eigen::Vector3d p(rng.uniform(box.min.x * res, (box.max.x + 1) * res),
                            rng.uniform(box.min.y * res, (box.max.y + 1) * res),
                            rng.uniform(box.min.z * res, (box.max.z + 1) * res));
    if (grid.state(p) == map::VoxelState::kFree) points.push_back(p);
  }
  if (points.empty()) {
    std::printf("kernels: no free voxel to time at\n");
    return;
  }
  GainEvaluator gains(config.gain);
  GainStats stats;
  auto t0 = std::chrono::steady_clock::now();
  double total = 0;
  int64_t counted = 0;
  for (const Eigen::Vector3d& p : points) {
    const NodeGain g = gains.evaluate(grid, p, &stats);
    total += g.gain;
    counted += g.total_voxels();
  }
  const double gain_ms = ms_since(t0);
  std::printf("kernel_gain_evaluation: %.3f ms\n", gain_ms / static_cast<double>(points.size()));
  std::printf("kernel_gain_ray_step: %.2f ns\n", 1e6 * gain_ms / static_cast<double>(stats.steps));
  std::printf("kernel_gain_checksum: %.0f weighted voxels\n", total);
  std::printf("kernel_gain_steps: %.0f voxels stepped, %.0f counted per evaluation\n",
              static_cast<double>(stats.steps) / static_cast<double>(points.size()),
              static_cast<double>(counted) / static_cast<double>(points.size()));
  // Edges from each point towards the next, 2 m at most, read every centimetre as samples_free does
  // where the coarse points fall short: a fresh checker each time (cold cache, as after new data).
  const CollisionConfig& cc = config.collision;
  // Just above the cache's cap (0.75 m with the defaults), the uncached path: the same 10-voxel
  // search reach, one cube search per centre.
  const double cached_cap = 0.6, search_cap = 0.76;
  for (int mode = 0; mode < 2; ++mode) {
    CollisionChecker checker(cc);
    checker.set_grid(&grid);
    int64_t reads = 0;
    double sum = 0;
    t0 = std::chrono::steady_clock::now();
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const Eigen::Vector3d a = points[i], d = points[i + 1] - a;
      const double len = std::min(2.0, d.norm());
      if (len < 1e-6) continue;
      const Eigen::Vector3d u = d / d.norm();
      for (double s = 0; s <= len; s += CollisionChecker::kFineStep, ++reads)
        sum += std::min(0.6, checker.esdf(a + s * u, mode == 0 ? cached_cap : search_cap));
    }
    const double ms = ms_since(t0);
    std::printf("kernel_esdf_%s: %.3f us per point (%lld points, checksum %.3f)\n",
                mode == 0 ? "chunk_cache" : "cube_search", 1e3 * ms / static_cast<double>(reads),
                static_cast<long long>(reads), sum);
  }
}

// The evaluator's object voxels: occupied voxels of T whose cube overlaps an object's box.
std::vector<map::VoxelKey> object_surface(const SyntheticWorld& world, const SyntheticTruth& truth) {
  std::vector<map::VoxelKey> keys;
  const map::KeyMath km(world.resolution());
  const double half = 0.5 * world.resolution();
  std::set<map::VoxelKey> seen;
  for (const Box& b : world.objects()) {
    const map::VoxelKey lo = km.key(b.min), hi = km.key(b.max);
    for (int32_t z = lo.z; z <= hi.z; ++z)
      for (int32_t y = lo.y; y <= hi.y; ++y)
        for (int32_t x = lo.x; x <= hi.x; ++x) {
          const map::VoxelKey k{x, y, z};
          const Eigen::Vector3d c = km.center(k);
          if (((c.array() + half) <= b.min.array()).any() || ((c.array() - half) >= b.max.array()).any())
            continue;
          if (world.occupied(k) && truth.target(k) && seen.insert(k).second) keys.push_back(k);
        }
  }
  return keys;
}

// The objects' surface voxels seen, in all and by height (0.5 m bands from 0, the last one open):
// where Time_o's 75 % waits (docs/evaluation.md, "What Time_o is made of").
struct ObjectsSeen {
  int64_t seen = 0;
  std::array<int64_t, 5> band_all{}, band_unseen{};
  std::string describe(size_t total) const {
    std::ostringstream o;
    o << std::fixed << std::setprecision(1)
      << 100.0 * static_cast<double>(seen) / static_cast<double>(std::max<size_t>(1, total))
      << " % seen; unseen/all by height 0-0.5/0.5-1/1-1.5/1.5-2/2+ m:";
    for (size_t b = 0; b < band_all.size(); ++b) o << ' ' << band_unseen[b] << '/' << band_all[b];
    return o.str();
  }
};
ObjectsSeen objects_seen(const map::StateGrid& known, const std::vector<map::VoxelKey>& keys) {
  ObjectsSeen s;
  map::StateGrid::Reader rd = known.reader();
  const map::KeyMath& km = known.keys();
  for (const map::VoxelKey& k : keys) {
    const size_t b = static_cast<size_t>(std::clamp(static_cast<int>(std::floor(km.center(k).z() / 0.5)), 0,
                                                    static_cast<int>(s.band_all.size()) - 1));
    ++s.band_all[b];
    if (rd.state(k) == map::VoxelState::kUnknown)
      ++s.band_unseen[b];
    else
      ++s.seen;
  }
  return s;
}

#ifdef SEMX_PERF_WITH_SIMULATOR
// The simulator's world the closed loop explores, when it is one (for the run folder's pictures).
std::optional<semx::simulator::World> g_sim_world;
#endif

std::unique_ptr<SyntheticWorld> make_world(const std::string& name, double resolution) {
  if (name == "apartment") return std::make_unique<SyntheticWorld>(SyntheticWorld::apartment(resolution));
  if (name == "two_rooms") return std::make_unique<SyntheticWorld>(SyntheticWorld::two_rooms(resolution));
#ifdef SEMX_PERF_WITH_SIMULATOR
  const semx::simulator::World w = semx::simulator::load_world(semx::simulator::shipped_world_path(name));
  g_sim_world = w;
  auto gt = std::make_shared<semx::simulator::GroundTruth>(w, resolution);
  Box interior{w.bounds.min, w.bounds.max};
  auto world = std::make_unique<SyntheticWorld>(
      resolution, interior,
      [gt](const semx::map::VoxelKey& k) {
        const Eigen::Vector3i key(k.x, k.y, k.z);
        return gt->in_grid(key) && gt->cell(key) == semx::simulator::GroundTruth::kOccupied;
      },
      w.start.position, w.name);
  std::vector<Box> objects;
  std::vector<int> classes;
  for (const semx::simulator::ObjectInfo& o : gt->objects()) {
    objects.push_back({o.center - 0.5 * o.extent, o.center + 0.5 * o.extent});
    classes.push_back(static_cast<int>(o.cls));
  }
  world->set_objects(std::move(objects), std::move(classes));
  return world;
#else
  throw ArgError("unknown world '" + name + "' (apartment, two_rooms; env1-3 need the simulator library)");
#endif
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-perf-planner", [&] {
    std::string world_name = "apartment", planner_name, config_file;
    int64_t samples = 0, seed = -1, runs = 1;
    double max_time = 900.0, semantic_weight = 0.0, coverage_period = 1.0;
    bool fit = false, verbose = false, kernels = false, oracle = false, semantics = false, time_split = false;
    std::string semantics_config, out_dir;
    std::vector<std::string> overrides;
    ArgParser p("semx-perf-planner", "Planning cycle time over whole explorations of synthetic worlds.");
    p.option("world", "NAME",
             "apartment (default), two_rooms, env1, env2, env3, or a world file (semx-world gen)",
             &world_name)
        .option("planner", "NAME",
                "semantic-dep (default), dep, nbv, aep, fuel, oracle (reads the world's truth)",
                &planner_name)
        .option("samples", "N", "sampling density (default: config, 45)", &samples)
        .option("seed", "N", "first seed (runs use seed, seed+1, ...)", &seed)
        .option("runs", "N", "explorations (default 1)", &runs)
        .option("max-time", "S", "simulated seconds per exploration at most (default 900)", &max_time)
        .option("semantic-weight", "W",
                "emulated semantics: every object of the world is a region of this weight (default 0: none)",
                &semantic_weight)
        .option("coverage-period", "S",
                "simulated seconds between coverage samples, the resolution of "
                "run_time_to_85 and run_time_to_95 (default 1)",
                &coverage_period)
        .option("config", "FILE", "planner YAML", &config_file)
        .repeated("set", "KEY=VALUE", "override a planner config key", &overrides)
        .flag("fit", "print least-squares charge coefficients", &fit)
        .flag("verbose", "one line per cycle", &verbose)
        .flag("oracle-interiors", "voxels inside the world's objects are unobservable from the start",
              &oracle)
        .flag("kernels", "time the gain and ESDF kernels on the first run's final map", &kernels)
        .flag("semantics", "emulated semantics with the semantics module's class table (weights, radii)",
              &semantics)
        .option("semantics-config", "FILE", "semantics YAML for --semantics (default: the built-in defaults)",
                &semantics_config)
        .flag("time-split", "print where each run's time went: new space, revisits, turns, hover, end game",
              &time_split)
        .option("out", "DIR",
                "write each run's folder under DIR/runs/ (metrics.json, ...) for semx-bench-report",
                &out_dir);
    if (!p.parse(argc, argv)) return 0;
    // run_time_to_85 is read off these samples, so without them the figure would silently be -1.
    if (!(coverage_period > 0)) throw ArgError("--coverage-period: must be positive");
    if (!planner_name.empty()) overrides.push_back("planner=" + planner_name);
    if (samples > 0) overrides.push_back("sampling.samples=" + std::to_string(samples));
    PlannerConfig config = load_config<PlannerConfig>(config_file, overrides);
    if (seed >= 0) config.seed = seed;
    const double resolution = 0.1;
    const auto world = make_world(world_name, resolution);
    std::function<bool(int, const Eigen::Vector3d&, double*, double*)> region_params;
    if (semantics || !semantics_config.empty()) {
#ifdef SEMX_PERF_WITH_SEMANTICS
      semx::semantics::SemanticsConfig sc;
      if (!semantics_config.empty()) sc = load_config<semx::semantics::SemanticsConfig>(semantics_config, {});
      region_params = [regions = sc.regions](int cls, const Eigen::Vector3d& extent, double* w, double* r) {
        const auto c = static_cast<semx::runtime::SemanticClass>(cls);
        if (cls <= 0 || cls >= static_cast<int>(semx::runtime::SemanticClass::kCount) ||
            !regions.of(c).enabled)
          return false;
        *w = semx::semantics::region_weight(regions, c);
        *r = semx::semantics::region_radius(regions, c, extent);
        return true;
      };
#else
      throw ArgError("--semantics needs the semantics library at build time");
#endif
    }
    std::vector<double> cycle_cpu_ms, cycle_ms, sample_ms, connect_ms, gain_ms, search_ms, charged_ms, evals;
    std::vector<CycleCounters> counters;
    double coverage = 0, time_s = 0, distance = 0, time_85 = 0, time_95 = 0, objects_time = 0;
    int64_t reached_85 = 0, reached_95 = 0, objects_done = 0, objects_completed = 0;
    int64_t collisions = 0, done = 0, paths = 0;
    const auto wall0 = std::chrono::steady_clock::now();
    for (int64_t run = 0; run < runs; ++run) {
      PlannerConfig c = config;
      c.seed = config.seed + run;
      ExplorationPlanner planner(c);
      ExplorationSimOptions o;
      o.max_time = max_time;
      o.semantic_weight = semantic_weight;
      o.region_params = region_params;
      o.coverage_period = coverage_period;
      if (oracle) {
        std::vector<semx::map::VoxelKey> keys;
        const double r = world->resolution();
        for (const Box& b : world->objects()) {
          const semx::map::KeyMath km(r);
          const auto lo = km.key(b.min), hi = km.key(b.max);
          for (int32_t x = lo.x; x <= hi.x; ++x)
            for (int32_t y = lo.y; y <= hi.y; ++y)
              for (int32_t z = lo.z; z <= hi.z; ++z) {
                const semx::map::VoxelKey k{x, y, z};
                const Eigen::Vector3d c = km.center(k);
                if (((c - b.min).array() > r).all() && ((b.max - c).array() > r).all() && world->occupied(k))
                  keys.push_back(k);
              }
        }
        planner.add_unobservable(keys);
        if (run == 0) std::printf("oracle_interior_voxels: %zu\n", keys.size());
      }
      // The known-map oracle reads the world's truth (its T: what the evaluator would count).
      const SyntheticTruth truth(*world);
      planner.set_truth(&truth);
      ExplorationSim sim(*world, planner, o);
      // Coverage of T (the evaluator's measure), twice a simulated second; Time_r and Time_95 read
      // on whole seconds as before. The objects' surface voxels in T (the evaluator's Time_o).
      const std::vector<semx::map::VoxelKey> object_voxels = object_surface(*world, truth);
      double t_cov_next = 0.0, t85 = -1.0, t95 = -1.0, t_o = -1.0;
      ObjectsSeen objects_at_95;
      std::vector<std::pair<double, double>> t_curve;
      semx::core::TimeSplit split;
      int64_t known_at_path = 0;
      const ExplorationSimResult r = sim.run([&](double t, const ExplorationPlanner::Output& out) {
        split.on_pose(t, sim.pose().position, sim.pose().yaw);
        if (t + 1e-9 >= t_cov_next) {
          const bool whole = std::abs(t_cov_next - std::round(t_cov_next)) < 1e-6;
          t_cov_next += 0.5;
          const int64_t covered = truth.covered(sim.known());
          const double cov =
              static_cast<double>(covered) / static_cast<double>(std::max<int64_t>(1, truth.target_count()));
          split.on_covered(t, covered);
          t_curve.emplace_back(t, cov);
          if (whole) {
            if (t85 < 0 && cov >= 0.85) t85 = t;
            if (t95 < 0 && cov >= 0.95) {
              t95 = t;
              objects_at_95 = objects_seen(sim.known(), object_voxels);
            }
            if (t_o < 0 && !object_voxels.empty()) {
              const ObjectsSeen o = objects_seen(sim.known(), object_voxels);
              if (static_cast<double>(o.seen) >= 0.75 * static_cast<double>(object_voxels.size())) t_o = t;
            }
          }
        }
        if (verbose && out.path) {
          // What the goal just left behind added to the map: a goal's promise against its yield.
          const int64_t known = sim.known().known_voxels();
          std::printf("path t=%.2f grew=%lld known=%lld T=%.3f %%\n", t,
                      static_cast<long long>(known - known_at_path), static_cast<long long>(known),
                      100.0 * truth.coverage(sim.known()));
          known_at_path = known;
        }
        if (verbose && out.status && out.status->iteration > 0) {
          const StatusReport& s = *out.status;
          std::printf(
              "t=%7.2f it=%4lld %-10s nodes=%4d ms=%6.2f (s %.2f c %.2f g %.2f q %.2f) evals=%lld "
              "settled=%lld charged=%.1fms %s\n",
              t, static_cast<long long>(s.iteration), to_string(s.state), s.num_nodes, s.counters.total_ms,
              s.counters.sample_ms, s.counters.connect_ms, s.counters.gain_ms, s.counters.search_ms,
              static_cast<long long>(s.counters.gain_evaluations),
              static_cast<long long>(s.counters.search_settled), 1e3 * s.charged_s, s.reason.c_str());
        }
      });
      if (kernels && run == 0) time_kernels(sim.known(), c);
      if (const auto* os = dynamic_cast<const OracleStrategy*>(&planner.strategy())) {
        const auto [t_share, obs_share] = os->coverage(sim.known());
        std::printf("oracle: %s\n", os->summary().describe().c_str());
        std::printf("oracle_viewpoints_flown: %zu of %zu (%lld skipped)\n", os->next_viewpoint(),
                    os->tour().size(), static_cast<long long>(os->skipped()));
        std::printf("oracle_coverage_of_observable: %.2f %%\n", 100.0 * obs_share);
        std::printf("oracle_coverage_of_T: %.2f %%\n", 100.0 * t_share);
      }
      for (size_t i = 0; i < r.cycle_ms.size(); ++i) {
        const CycleCounters& k = r.counters[i];
        cycle_ms.push_back(r.cycle_ms[i]);
        cycle_cpu_ms.push_back(k.cpu_ms);
        sample_ms.push_back(k.sample_ms);
        connect_ms.push_back(k.connect_ms);
        gain_ms.push_back(k.gain_ms);
        search_ms.push_back(k.search_ms);
        charged_ms.push_back(1e3 * charged_seconds(k, c.charge));
        evals.push_back(static_cast<double>(k.gain_evaluations));
        counters.push_back(k);
      }
      coverage += r.coverage;
      objects_completed += r.objects_completed;
      if (r.objects_time >= 0) {
        objects_time += r.objects_time;
        ++objects_done;
      }
      std::printf("run_time_to_85: %.1f s\n", r.time_85);
      std::printf("run_end_game: %.1f s of %.1f s (settled at %.1f s, coverage %.2f %%)\n",
                  r.time_s - r.time_settled, r.time_s, r.time_settled, 100.0 * r.coverage);
      const double final_t = truth.coverage(sim.known());
      std::printf("run_T_coverage: %.2f %% (85 %% at %.0f s, 95 %% at %.0f s, end %.1f s)\n", 100.0 * final_t,
                  t85, t95, r.time_s);
      std::printf("run_T_time_o: %.0f s (75 %% of %zu object surface voxels)\n", t_o, object_voxels.size());
      if (!object_voxels.empty()) {
        if (t95 >= 0)
          std::printf("run_T_objects_at_95: %s\n", objects_at_95.describe(object_voxels.size()).c_str());
        std::printf("run_T_objects_at_end: %s\n",
                    objects_seen(sim.known(), object_voxels).describe(object_voxels.size()).c_str());
      }
      split.on_covered(r.time_s, truth.covered(sim.known()));
      double settled = r.time_s;
      for (const auto& [t, c] : t_curve) {
        if (c >= final_t - 0.005) {
          settled = t;
          break;
        }
      }
      // One line per run for scripts: the evaluator's figures on T.
      std::printf(
          "run_summary: world=%s planner=%s seed=%lld T=%.3f t85=%.1f t95=%.1f settled=%.1f time_f=%.1f "
          "end_game=%.1f distance=%.2f collisions=%lld done=%d\n",
          world->name().c_str(), c.planner.c_str(), static_cast<long long>(c.seed), 100.0 * final_t, t85, t95,
          settled, r.time_s, r.time_s - settled, r.distance, static_cast<long long>(r.collisions),
          r.done ? 1 : 0);
      const semx::core::TimeSplitResult ts =
          split.finish(r.time_s, settled, resolution * resolution * resolution);
      if (!out_dir.empty()) {
#ifdef SEMX_PERF_WITH_EVALUATOR
        namespace ev = semx::evaluator;
        ev::RunSummary s;
        s.info.world = world->name();
        s.info.world_path = world_name;
        s.info.planner = c.planner;
        s.info.seed = c.seed;
        s.info.samples = c.sampling.samples;
        s.info.source = "closed-loop";
        s.time_f_s = r.time_s;
        s.distance_m = r.distance;
        s.coverage_pct = 100.0 * final_t;
        if (t85 >= 0) s.time_r_s = t85;
        if (t95 >= 0) s.time_95_s = t95;
        s.time_settled_s = settled;
        s.end_game_s = std::max(0.0, r.time_s - settled);
        if (t_o >= 0) s.time_o_s = t_o;
        s.collisions = r.collisions;
        s.termination = r.done ? "planner_done" : "time_limit";
        s.planner_state = r.done ? "DONE" : "EXECUTING";
        s.planner_reason = r.reason;
        s.sim_s = r.time_s;
        s.time_limit_s = max_time;
        s.resolution_m = resolution;
        s.target_voxels = truth.target_count();
        s.covered_voxels = truth.covered(sim.known());
        for (const auto& [t, cov] : t_curve) {
          ev::CoverageSample cs;
          cs.t_s = t;
          cs.coverage_pct = 100.0 * cov;
          s.coverage.push_back(cs);
        }
        s.time_split = ts;
        std::string stem = world->name();
        for (char& ch : stem)
          if (ch == '/' || ch == ' ') ch = '_';
        const std::string dir = out_dir + "/runs/" + stem + "-" + c.planner + "-s" +
                                std::to_string(c.sampling.samples) + "-seed" + std::to_string(c.seed);
        ev::write_run_metrics(dir, s);
#ifdef SEMX_PERF_WITH_SIMULATOR
        if (g_sim_world)
          ev::time_split_picture(
              sim.known(), *g_sim_world, nullptr, ts,
              "where the time went: " + world->name() + ", " + c.planner + " (closed loop)")
              .write_png(dir + "/time_split.png");
#endif
#else
        throw ArgError("--out needs the evaluator library at build time");
#endif
      }
      if (time_split) {
        std::printf("run_time_split:");
        for (int u = 0; u < semx::core::kTimeUses; ++u)
          std::printf(" %s %.1f s %.1f m", semx::core::to_string(static_cast<semx::core::TimeUse>(u)),
                      ts.time_s[static_cast<size_t>(u)], ts.distance_m[static_cast<size_t>(u)]);
        std::printf(" | revisit_by_place %.1f m of %.1f m, time_f %.1f s, settled %.1f s\n",
                    ts.revisit_by_place_m, ts.distance_total_m, ts.time_f, ts.time_settled);
      }
      if (r.time_85 >= 0) {
        time_85 += r.time_85;
        ++reached_85;
      }
      std::printf("run_time_to_95: %.1f s\n", r.time_95);
      std::printf("run_coverage: %.2f %%\n", 100.0 * r.coverage);
      std::printf("run_collisions: %lld steps\n", static_cast<long long>(r.collisions));
      std::printf("run_end: %s at %.1f s\n", r.done ? "DONE" : "stopped", r.time_s);
      if (r.time_95 >= 0) {
        time_95 += r.time_95;
        ++reached_95;
      }
      time_s += r.time_s;
      distance += r.distance;
      collisions += r.collisions;
      paths += r.paths;
      done += r.done ? 1 : 0;
      if (verbose) {
        for (const auto& [t, c] : r.coverage_curve)
          std::printf("coverage_at %.1f s: %.2f %%\n", t, 100.0 * c);
      }
      if (verbose)
        std::printf("run %lld: %s after %.1f s: %s\n", static_cast<long long>(run),
                    r.done ? "DONE" : "stopped", r.time_s, r.reason.c_str());
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double n = static_cast<double>(runs);
    std::fprintf(stderr, "semx-perf-planner: world %s, planner %s\n", world->name().c_str(),
                 config.planner.c_str());
    std::printf("samples: %d candidates\n", config.sampling.samples);
    std::printf("runs: %lld explorations\n", static_cast<long long>(runs));
    std::printf("cycles: %zu cycles\n", cycle_ms.size());
    std::printf("cycle_cpu_p50: %.2f ms\n", percentile(cycle_cpu_ms, 0.5));
    std::printf("cycle_cpu_p95: %.2f ms\n", percentile(cycle_cpu_ms, 0.95));
    std::printf("cycle_cpu_max: %.2f ms\n", percentile(cycle_cpu_ms, 1.0));
    std::printf("cycle_p50: %.2f ms\n", percentile(cycle_ms, 0.5));
    std::printf("cycle_p95: %.2f ms\n", percentile(cycle_ms, 0.95));
    std::printf("cycle_max: %.2f ms\n", percentile(cycle_ms, 1.0));
    std::printf("cycle_mean: %.2f ms\n", mean(cycle_ms));
    std::printf("sample_mean: %.2f ms\n", mean(sample_ms));
    std::printf("connect_mean: %.2f ms\n", mean(connect_ms));
    std::printf("gain_mean: %.2f ms\n", mean(gain_ms));
    std::printf("search_mean: %.2f ms\n", mean(search_ms));
    std::printf("gain_evaluations_mean: %.1f evaluations\n", mean(evals));
    std::printf("charged_mean: %.2f ms\n", mean(charged_ms));
    std::printf("charged_p95: %.2f ms\n", percentile(charged_ms, 0.95));
    std::printf("coverage: %.1f %%\n", 100.0 * coverage / n);
    std::printf("done: %lld explorations\n", static_cast<long long>(done));
    std::printf("exploration_time: %.1f s\n", time_s / n);
    if (reached_85 > 0) std::printf("time_to_85: %.1f s\n", time_85 / static_cast<double>(reached_85));
    if (reached_95 > 0) std::printf("time_to_95: %.1f s\n", time_95 / static_cast<double>(reached_95));
    std::printf("distance: %.1f m\n", distance / n);
    if (semantic_weight > 0) {
      std::printf("objects_total: %zu objects\n", world->objects().size());
      std::printf("objects_observed: %.1f objects\n", static_cast<double>(objects_completed) / n);
    }
    if (objects_done > 0)
      std::printf("time_all_objects_observed: %.1f s\n", objects_time / static_cast<double>(objects_done));
    std::printf("paths: %.1f paths\n", static_cast<double>(paths) / n);
    std::printf("collisions: %lld steps\n", static_cast<long long>(collisions));
    std::printf("wall_time: %.1f s\n", wall_s);
    if (fit && counters.size() >= 6) {
      // cpu_ms ≈ base + box·a + evals·b + steps·c + settled·d.
      Eigen::MatrixXd A(static_cast<Eigen::Index>(counters.size()), 5);
      Eigen::VectorXd y(static_cast<Eigen::Index>(counters.size()));
      for (size_t i = 0; i < counters.size(); ++i) {
        const CycleCounters& k = counters[i];
        const Eigen::Index r = static_cast<Eigen::Index>(i);
        A(r, 0) = 1.0;
        A(r, 1) = static_cast<double>(k.box_checks);
        A(r, 2) = static_cast<double>(k.gain_evaluations);
        A(r, 3) = static_cast<double>(k.ray_steps);
        A(r, 4) = static_cast<double>(k.search_settled);
        y(r) = k.cpu_ms * 1e-3;
      }
      // Non-negative least squares by elimination: a negative coefficient is fixed at 0 and the
      // rest refitted (a cost cannot be negative).
      std::vector<bool> active(5, true);
      Eigen::VectorXd x = Eigen::VectorXd::Zero(5);
      for (int round = 0; round < 5; ++round) {
        std::vector<int> cols;
        for (int j = 0; j < 5; ++j)
          if (active[static_cast<size_t>(j)]) cols.push_back(j);
        Eigen::MatrixXd B(A.rows(), static_cast<Eigen::Index>(cols.size()));
        for (size_t j = 0; j < cols.size(); ++j) B.col(static_cast<Eigen::Index>(j)) = A.col(cols[j]);
        const Eigen::VectorXd z = B.colPivHouseholderQr().solve(y);
        x.setZero();
        int worst = -1;
        for (size_t j = 0; j < cols.size(); ++j) {
          x(cols[j]) = z(static_cast<Eigen::Index>(j));
          if (z(static_cast<Eigen::Index>(j)) < 0 &&
              (worst < 0 || z(static_cast<Eigen::Index>(j)) < x(worst)))
            worst = cols[j];
        }
        if (worst < 0) break;
        active[static_cast<size_t>(worst)] = false;
      }
      const Eigen::VectorXd res = A * x - y;
      std::printf("fit_base_s: %.3e s\n", x(0));
      std::printf("fit_per_box_check_s: %.3e s\n", x(1));
      std::printf("fit_per_gain_node_s: %.3e s\n", x(2));
      std::printf("fit_per_ray_step_s: %.3e s\n", x(3));
      std::printf("fit_per_search_node_s: %.3e s\n", x(4));
      std::printf("fit_rms_error: %.3f ms\n",
                  1e3 * std::sqrt(res.squaredNorm() / static_cast<double>(res.size())));
    }
    return 0;
  });
}
