// The paper's experiment as tables and plots: run folders of many explorations (one per world,
// planner, sampling density and seed, each with metrics.json and coverage.csv) summarised as
// mean ± std over seeds in the layout of the paper's Table II (sampling-density sweep) and
// Table III (planner comparison), a CSV of every run, and one coverage-over-time plot per world
// with every planner.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace semx::evaluator {

struct BenchRun {
  std::string dir;  // the run folder
  std::string world, planner, termination;
  int64_t seed = 0;
  int samples = 0;
  double time_f_s = 0, distance_m = 0, coverage_pct = 0, wall_s = 0, sim_s = 0;
  std::optional<double> time_r_s;        // never reached 85 %
  std::optional<double> time_o_s;        // objects never 75 % covered, or a run folder from before it
  std::optional<double> time_95_s;       // never reached 95 %, or a run folder from before it
  std::optional<double> time_settled_s;  // coverage within 0.5 points of its final value
  std::optional<double> end_game_s;      // time_f_s - time_settled_s
  std::optional<double> object_coverage_pct;
  int64_t collisions = 0;
  bool valid = true;           // metrics.json "valid" (a run folder from before it: true)
  std::string invalid_reason;  // why not
  std::vector<std::pair<double, double>> coverage;  // (t s, %)
  // time_split.json (empty when the folder has none): seconds of new, revisit, turn, hover and
  // end game, and the metres flown over ground flown before.
  std::vector<double> split_s;
  // ... and the same five up to Time_r (from the slices; empty when 85 % was never reached): where
  // the time to 85 % went, which the whole run's split hides under its end game.
  std::vector<double> split_to_r_s;
  double revisit_by_place_m = 0;
  // A process of the set was restarted during the run (metrics.json "disturbed"): listed under
  // the tables, never in them; `restarts` says which and when ("mapper 12.3 s, ...").
  bool disturbed = false;
  std::string restarts;
  // CPU seconds (user + system) of each process of the set, from the launcher's exit lines in
  // DIR/launch.log (a restarted process's lives summed); empty when the folder has none.
  std::map<std::string, double> cpu_s;
};

// Reads DIR/metrics.json and DIR/coverage.csv; throws std::runtime_error naming the file.
BenchRun load_bench_run(const std::string& dir);
// Every run folder below `root` (any depth) that has a metrics.json, sorted by path.
std::vector<BenchRun> load_bench_runs(const std::string& root);

struct Stat {
  double mean = 0, std = 0;  // sample standard deviation (0 for one value)
  int n = 0;
};
Stat stat_of(const std::vector<double>& values);

struct BenchReportOptions {
  std::string sweep_planner = "semantic-dep";  // the planner of the sampling-density table
  int comparison_samples = 45;                 // the density of the planner comparison
  double threshold_pct = 85.0;
};

// Worlds whose name starts with this (semx-world gen's names) are also compared as one set: the
// runs paired by world and seed, differences relative to the baseline's run.
inline constexpr const char* kGeneratedPrefix = "generated";

// Markdown (only the valid, undisturbed runs; the others are listed under the tables): the sweep
// table, the comparison table (with Time_95, the end game and Time_o, the
// objects' 75 %, after the paper's columns), every planner's times and distance as multiples of
// the known-map oracle's (where the bench ran `oracle`), and semantic-dep's margins over each
// baseline (Time_f, Time_r, Time_o, Distance, in %), each world in the order the runs name them.
std::string bench_markdown(const std::vector<BenchRun>& runs, const BenchReportOptions& options = {});
// Two benches of the same runs, e.g. a change against main or a config against its default:
// `runs` (A) against `baseline` (B), each run of A paired with B's run of the same world,
// planner, seed and density (valid, undisturbed runs at the comparison density only). Per
// planner and over all planners: collisions, runs ended DONE and the least coverage in A and B;
// Time_r, Time_95, Time_o and Time_f paired (as the seed-by-seed table: sooner / same / later,
// mean difference and relative difference with 95 % intervals) over every world, over the
// generated worlds and per other world; then every pair; then the runs without a partner.
std::string bench_against_markdown(const std::vector<BenchRun>& runs, const std::vector<BenchRun>& baseline,
                                   const BenchReportOptions& options = {});
// One row per run (the columns of metrics.csv plus the folder).
std::string bench_csv(const std::vector<BenchRun>& runs);
// Coverage curves of several runs ((t s, %), t increasing) at 0, step_s, ... up to t_max_s:
// their mean, minimum and maximum at each step; a run that ended holds its final coverage, and
// before its first sample it counts as 0.
struct SeedSpread {
  std::vector<double> t, mean, lo, hi;
};
SeedSpread spread_over_seeds(const std::vector<std::vector<std::pair<double, double>>>& curves,
                             double t_max_s, double step_s = 1.0);

// DIR/coverage_WORLD.png per world (valid, undisturbed runs): every planner's mean coverage
// curve over seeds at the comparison density, with a shaded band from the lowest to the highest
// seed's curve where it has more than one seed. Returns the files written.
std::vector<std::string> write_bench_plots(const std::vector<BenchRun>& runs, const std::string& dir,
                                           const BenchReportOptions& options = {});

// The run whose map a planner's montage tile shows: of its seeds, the one with the median final
// coverage (the lower of the two middle ones for an even count; ties by seed).
const BenchRun* median_coverage_run(std::vector<const BenchRun*> runs);

// DIR/maps_WORLD.png per world (the same runs): a grid of one map.png per planner
// (median_coverage_run), each titled with the planner, the seed, its coverage and Time_95.
// Run folders without a readable map.png get a grey tile and are listed in *missing ("FILE:
// why"). Returns the files written.
std::vector<std::string> write_bench_montages(const std::vector<BenchRun>& runs, const std::string& dir,
                                              const BenchReportOptions& options = {},
                                              std::vector<std::string>* missing = nullptr);

}  // namespace semx::evaluator
