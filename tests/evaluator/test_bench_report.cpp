// The bench report: run folders read back, mean ± std over seeds, runs that never reached a
// threshold, the margins of semantic-dep over each baseline, and files that name their errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/bench_report.hpp"
#include "semx/evaluator/montage.hpp"
#include "semx/evaluator/rgb.hpp"

namespace semx::evaluator {
namespace {

namespace fs = std::filesystem;

std::string json_or_null(std::optional<double> v) { return v ? std::to_string(*v) : "null"; }

// One run folder as the evaluator writes it (the fields the report reads).
void write_run(const std::string& root, const std::string& world, const std::string& planner, int seed,
               double time_f, std::optional<double> time_r, std::optional<double> time_o,
               bool with_objects = true, std::optional<double> time_95 = std::nullopt,
               std::optional<double> end_game = std::nullopt) {
  const fs::path dir = fs::path(root) / (world + "-" + planner + "-s45-seed" + std::to_string(seed));
  fs::create_directories(dir);
  std::ofstream m(dir / "metrics.json");
  m << "{\n  \"world\": \"" << world << "\",\n  \"planner\": \"" << planner << "\",\n  \"seed\": " << seed
    << ",\n  \"samples\": 45,\n  \"time_f_s\": " << time_f << ",\n  \"distance_m\": " << 2 * time_f
    << ",\n  \"coverage_pct\": 95,\n  \"time_r_s\": " << json_or_null(time_r) << ",\n";
  if (with_objects) m << "  \"object_coverage_pct\": 80,\n  \"time_o_s\": " << json_or_null(time_o) << ",\n";
  if (time_95) m << "  \"time_95_s\": " << *time_95 << ",\n";
  if (end_game)
    m << "  \"end_game_s\": " << *end_game << ",\n  \"time_settled_s\": " << time_f - *end_game << ",\n";
  m << "  \"collisions\": 0,\n  \"wall_s\": 10,\n  \"sim_s\": " << time_f
    << ",\n  \"termination\": \"planner_done\"\n}\n";
  std::ofstream c(dir / "coverage.csv");
  c << "t_s,coverage_pct,distance_m,covered_voxels,object_coverage_pct\n0,0,0,0,0\n"
    << time_f << ",95,1,10,80\n";
}

TEST(BenchReport, TablesGiveMeansOverSeedsAndTheMarginsOfSemanticDep) {
  const std::string root = test::temp_dir("bench_report");
  // env1: semantic-dep 10 and 20 s to 85 % (mean 15), dep 20 and 40 (mean 30): -50 %.
  write_run(root, "env1", "semantic-dep", 1, 100, 10, 30);
  write_run(root, "env1", "semantic-dep", 2, 100, 20, 50);
  write_run(root, "env1", "dep", 1, 200, 20, 60);
  write_run(root, "env1", "dep", 2, 200, 40, std::nullopt);  // objects never at 75 %
  // nbv never reaches 85 %, and its folders come from before object coverage.
  write_run(root, "env1", "nbv", 1, 50, std::nullopt, std::nullopt, false);
  // What semx-bench set aside when it ran a stopped run again is not read.
  write_run(root + "/interrupted", "env1", "dep", 1, 999, 1, 1);
  const auto runs = load_bench_runs(root);
  ASSERT_EQ(runs.size(), 5u);
  for (const auto& r : runs) EXPECT_EQ(r.object_coverage_pct.has_value(), r.planner != "nbv") << r.dir;

  const std::string md = bench_markdown(runs);
  // Planner rows: Time_r mean ± sample std; Time_o over the runs that reached it, with the count.
  EXPECT_NE(
      md.find("| env1 | semantic-dep | 2 | 100.00 ± 0.00 | 200.00 ± 0.00 | 95.00 ± 0.00 | 15.00 ± 7.07 | 0 | "
              "40.00 ± 14.14 |"),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| env1 | dep | 2 | 200.00 ± 0.00 | 400.00 ± 0.00 | 95.00 ± 0.00 | 30.00 ± 14.14 | 0 | "
                    "60.00 (1/2) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| env1 | nbv | 1 | 50.00 | 100.00 | 95.00 | N/A | 0 | N/A |"), std::string::npos) << md;
  // Margins: Time_f -50 %, Time_r -50 %, Time_o -33.3 % (40 against 60), distance -50 %.
  EXPECT_NE(md.find("| env1 | dep | -50.0 % | -50.0 % | -33.3 % | -50.0 % | +0.00 |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| env1 | nbv | +100.0 % | only ours reached 85 % | only ours reached 75 % |"),
            std::string::npos)
      << md;

  const std::string csv = bench_csv(runs);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s,sim_s,"
            "termination,dir,object_coverage_pct,time_o_s,time_95_s,time_settled_s,end_game_s,disturbed");
  // A run folder from before Time_95 and the end game leaves their columns empty.
  EXPECT_NE(csv.find(",80.000,30.000,,,,false\n"), std::string::npos) << csv;
}

// Seed by seed: only seeds both reached 85 % in count; ties within 0.05 s are the same flight;
// the interval is the paired mean difference ± t(0.975, n-1) · sd / √n.
TEST(BenchReport, SeedBySeedComparisonCountsWinsAndGivesTheIntervalOfTheDifference) {
  const std::string root = test::temp_dir("bench_report_paired");
  const double ours[] = {10, 20, 30, 40, 50}, dep[] = {12, 20.04, 35, 41, -1}, aep[] = {5, 6, 7, 8, 9};
  for (int seed = 1; seed <= 5; ++seed) {
    // Time_o: ours 1 s everywhere, the baselines 2 s (aep) and 1 s (dep).
    write_run(root, "env2", "semantic-dep", seed, 100, ours[seed - 1], 1);
    // dep's seed 5 never reached 85 %: left out of the pairs.
    write_run(root, "env2", "dep", seed, 100,
              dep[seed - 1] < 0 ? std::nullopt : std::optional<double>(dep[seed - 1]), 1);
    if (seed <= 3) write_run(root, "env2", "aep", seed, 100, aep[seed - 1], 2);
  }
  const std::string md = bench_markdown(load_bench_runs(root));
  // Differences -2, -0.04, -5, -1: 3 sooner, 1 the same; mean -2.01, sd 2.148, t(3) 3.182.
  EXPECT_NE(md.find("| env2 | dep | Time_r | 4 | 3 / 1 / 0 | -2.01 | [-5.43, 1.41] |"), std::string::npos)
      << md;
  // Time_o pairs all five seeds (dep's seed 5 reached 75 % of the objects): the same each time.
  EXPECT_NE(md.find("| env2 | dep | Time_o | 5 | 0 / 5 / 0 | +0.00 | [0.00, 0.00] |"), std::string::npos)
      << md;
  // Later in all three seeds aep ran: +5, +14, +23; mean 14, sd 9, t(2) 4.303: [-8.4, 36.4].
  EXPECT_NE(md.find("| env2 | aep | Time_r | 3 | 0 / 0 / 3 | +14.00 | [-8.36, 36.36] |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| env2 | aep | Time_o | 3 | 3 / 0 / 0 | -1.00 | [-1.00, -1.00] |"), std::string::npos)
      << md;
}

// Generated worlds are also compared as one set, each run paired with the baseline's run of
// the same world and seed, with the relative difference; time_split.json becomes a table.
TEST(BenchReport, GeneratedWorldsArePooledAndTheTimeSplitIsTabled) {
  const std::string root = test::temp_dir("bench_report_generated");
  write_run(root, "generated-s1-a50-r1", "semantic-dep", 1, 100, 10, 1);
  write_run(root, "generated-s1-a50-r1", "dep", 1, 100, 20, 1);
  write_run(root, "generated-s2-a90-r3", "semantic-dep", 1, 100, 30, 1);
  write_run(root, "generated-s2-a90-r3", "dep", 1, 100, 40, 1);
  write_run(root, "env1", "semantic-dep", 1, 100, 5, 1);  // not generated: not in the set
  write_run(root, "env1", "dep", 1, 100, 50, 1);
  const fs::path split = fs::path(root) / "generated-s1-a50-r1-dep-s45-seed1" / "time_split.json";
  std::ofstream(split) << "{\"revisit_by_place_m\": 7.5, \"uses\": {\"new\": {\"time_s\": 40}, \"revisit\": "
                          "{\"time_s\": 30}, \"turn\": {\"time_s\": 10}, \"hover\": {\"time_s\": 0}, "
                          "\"end_game\": {\"time_s\": 20}}, \"slice_s\": 6, \"slices\": \"nrntnnhh\"}\n";
  const std::string md = bench_markdown(load_bench_runs(root));
  // Differences -10 and -10 s; relative -50 % and -25 %: mean -37.5, sd 17.68, t(1) 12.706. As a
  // share of dep's mean time (20 and 40 s: 30 s), -10 s is -33.3 % in both pairs.
  EXPECT_NE(
      md.find("| generated (2 worlds) | dep | Time_r | 2 | 2 / 0 / 0 | -10.00 | [-10.00, -10.00] | -37.5 | "
              "[-196.3, 121.3] | -33.3 | [-33.3, -33.3] |"),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| generated-s1-a50-r1 | dep | 1 | 40.0 | 30.0 | 10.0 | 0.0 | 20.0 | 100.0 | 7.5 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| generated (2 worlds) | dep | 1 | 40.0 |"), std::string::npos) << md;
  // Up to Time_r (20 s) from the 6 s slices: new 0-6 and 12-18, revisit 6-12, then 2 s of the turn.
  EXPECT_NE(md.find("| generated-s1-a50-r1 | dep | 1 | 12.0 | 6.0 | 2.0 | 0.0 | 20.0 |\n"), std::string::npos)
      << md;
  // Without the slices (a folder from before them) there is no such table.
  std::ofstream(split) << "{\"revisit_by_place_m\": 0, \"uses\": {\"new\": {\"time_s\": 1}, \"revisit\": "
                          "{\"time_s\": 0}, \"turn\": {\"time_s\": 0}, \"hover\": {\"time_s\": 0}, "
                          "\"end_game\": {\"time_s\": 0}}}\n";
  EXPECT_EQ(bench_markdown(load_bench_runs(root)).find("Up to Time_r"), std::string::npos);
  // A slice letter the report does not know names the file.
  std::ofstream(split) << "{\"revisit_by_place_m\": 0, \"uses\": {\"new\": {\"time_s\": 1}, \"revisit\": "
                          "{\"time_s\": 0}, \"turn\": {\"time_s\": 0}, \"hover\": {\"time_s\": 0}, "
                          "\"end_game\": {\"time_s\": 0}}, \"slice_s\": 6, \"slices\": \"nx\"}\n";
  try {
    load_bench_runs(root);
    ADD_FAILURE() << "an unknown slice use was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("time_split.json: unknown slice use 'x'"), std::string::npos)
        << e.what();
  }
}

TEST(BenchReport, EveryPlannerIsDividedByTheOracleAndTheEndGameIsTabled) {
  const std::string root = test::temp_dir("bench_report_oracle");
  // oracle: Time_r 10, Time_95 20, distance 2 x 50 = 100 m. dep: Time_r 30, Time_95 50 (the mean of
  // 40 and 60), distance 2 x 200 = 400 m.
  write_run(root, "env2", "oracle", 1, 50, 10, std::nullopt, true, 20, 1);
  write_run(root, "env2", "dep", 1, 200, 30, std::nullopt, true, 40, 100);
  write_run(root, "env2", "dep", 2, 200, 30, std::nullopt, true, 60, 120);
  write_run(root, "env2", "nbv", 1, 300, std::nullopt, std::nullopt, true);
  write_run(root, "env2", "fuel", 1, 40, 8, std::nullopt, true, 25, 1);  // sooner to 85 %, not to 95 %
  const auto runs = load_bench_runs(root);
  ASSERT_EQ(runs.size(), 5u);
  const std::string md = bench_markdown(runs);
  EXPECT_NE(md.find("| env2 | dep | 3.00 | 2.50 | 4.00 | 0 / 0 of 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| env2 | nbv | N/A | N/A | 6.00 | 0 / 0 of 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| env2 | fuel | 0.80 | 1.25 | 0.80 | 1 / 0 of 1 |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| env2 | oracle | N/A"), std::string::npos) << md;  // not divided by itself
  // The comparison table ends with Time_95 and the end game.
  EXPECT_NE(md.find("| 50.00 ± 14.14 | 110.00 ± 14.14 |"), std::string::npos) << md;
  const std::string csv = bench_csv(runs);
  EXPECT_NE(csv.find("time_95_s,time_settled_s,end_game_s,disturbed\n"), std::string::npos);
  EXPECT_NE(csv.find(",40.000,100.000,100.000,false\n"), std::string::npos) << csv;
  // Without an oracle run there is no such table.
  fs::remove_all(fs::path(root) / "env2-oracle-s45-seed1");
  EXPECT_EQ(bench_markdown(load_bench_runs(root)).find("known-map oracle"), std::string::npos);
}

// A run during which a process died and was restarted is no sample of the planner: it stays out
// of every table and plot and is listed under them with what restarted when.
TEST(BenchReport, DisturbedRunsAreListedUnderTheTablesNotInThem) {
  const std::string root = test::temp_dir("bench_disturbed");
  write_run(root, "env1", "semantic-dep", 1, 100, 10, 30);
  write_run(root, "env1", "semantic-dep", 2, 100, 20, 50);
  write_run(root, "env1", "semantic-dep", 3, 300, 90, 90);
  {
    // Seed 3 was disturbed: the evaluator's two fields, as it writes them.
    const std::string m = root + "/env1-semantic-dep-s45-seed3/metrics.json";
    std::ifstream in(m);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.insert(text.find("  \"termination\""),
                "  \"disturbed\": true,\n  \"restarts\": [{\"node\": \"mapper\", \"t_s\": 12.5, "
                "\"restarts\": 1}],\n");
    std::ofstream(m) << text;
  }
  const auto runs = load_bench_runs(root);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_TRUE(runs[2].disturbed);
  EXPECT_EQ(runs[2].restarts, "mapper 12.5 s");
  const std::string md = bench_markdown(runs);
  EXPECT_NE(md.find("| env1 | semantic-dep | 2 | 100.00 ± 0.00 |"), std::string::npos)
      << "the table has the two undisturbed seeds:\n"
      << md;
  const auto listed = md.find("### Disturbed runs");
  ASSERT_NE(listed, std::string::npos) << md;
  EXPECT_NE(md.find("| env1 | semantic-dep | 45 | 3 | mapper 12.5 s | 300.00 |", listed), std::string::npos)
      << md;
  EXPECT_NE(bench_csv(runs).find(",true\n"), std::string::npos) << "the CSV keeps every run, marked";
}

// Replaces `from` with `to` in a run folder's metrics.json (write_run's fixed fields).
void edit_run(const std::string& root, const std::string& run, const std::string& from,
              const std::string& to) {
  const fs::path file = fs::path(root) / run / "metrics.json";
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << file;
  text.replace(at, from.size(), to);
  std::ofstream(file) << text;
}

// Two benches of the same runs: each run of A paired with B's of the same world, planner and
// seed; the paired differences with their intervals per planner, over all and per set of worlds;
// collisions, DONE and the least coverage of each side; the runs without a partner listed.
TEST(BenchReport, TheCostTableSumsEachProcesssCpuPerPlanner) {
  const std::string root = test::temp_dir("bench_report_cost");
  write_run(root, "env1", "dep", 1, 100, 10, 30);
  write_run(root, "env1", "dep", 2, 50, 10, 30);
  write_run(root, "env1", "fuel", 1, 80, 10, 30);
  auto launch_log = [&](const std::string& run, const std::string& text) {
    std::ofstream(fs::path(root) / run / "launch.log") << text;
  };
  // A restarted mapper's two lives are summed; lines that are no exit lines, or exit lines from
  // before the CPU figures, are not read.
  launch_log(
      "env1-dep-s45-seed1",
      "[semx-launch] mapper: started (pid 12)\n"
      "[semx-launch] mapper: killed by signal Killed (peak RSS 100 MB, CPU 3.0 s user + 1.0 s system)\n"
      "[semx-launch] mapper: exited with 0 (peak RSS 120 MB, CPU 10.0 s user + 2.0 s system)\n"
      "[semx-launch] planner: exited with 0 (peak RSS 42 MB, CPU 5.5 s user + 0.5 s system)\n"
      "[semx-launch] evaluator: exited with 0 (peak RSS 80 MB)\n");
  launch_log("env1-dep-s45-seed2",
             "[semx-launch] mapper: exited with 0 (peak RSS 120 MB, CPU 4.0 s user + 0.0 s system)\n"
             "[semx-launch] planner: exited with 0 (peak RSS 42 MB, CPU 2.0 s user + 1.0 s system)\n");
  launch_log("env1-fuel-s45-seed1",
             "[semx-launch] planner: exited with 0 (peak RSS 42 MB, CPU 8.0 s user + 0.0 s system)\n"
             "[semx-launch] ros_bridge: exited with 0 (peak RSS 30 MB, CPU 1.0 s user + 0.0 s system)\n");
  const auto runs = load_bench_runs(root);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_DOUBLE_EQ(runs[0].cpu_s.at("mapper"), 16.0);
  EXPECT_EQ(runs[0].cpu_s.count("evaluator"), 0u);

  const std::string md = bench_markdown(runs);
  ASSERT_NE(md.find("### What the runs cost"), std::string::npos) << md;
  // The set's processes first, in set order, then the others by name.
  EXPECT_NE(md.find("| mapper | planner | ros_bridge | CPU s |"), std::string::npos) << md;
  // dep: 2 runs, 150 simulated s, 20 wall s; mapper 16 + 4, planner 6 + 3, 29 s in all.
  EXPECT_NE(md.find("| dep | 2 | 150 | 20 | 20.0 | 9.0 | - | 29.0 | 0.193 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| fuel | 1 | 80 | 10 | - | 8.0 | 1.0 | 9.0 | 0.113 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| all | 3 | 230 | 30 | 20.0 | 17.0 | 1.0 | 38.0 | 0.165 |"), std::string::npos) << md;

  // Folders without a launch.log (older benches) give no cost table.
  const std::string bare = test::temp_dir("bench_report_cost_bare");
  write_run(bare, "env1", "dep", 1, 100, 10, 30);
  EXPECT_EQ(bench_markdown(load_bench_runs(bare)).find("What the runs cost"), std::string::npos);
}

TEST(BenchReport, AgainstABaselineBenchPairsEachRunWithItsTwin) {
  const std::string a = test::temp_dir("bench_against_a"), b = test::temp_dir("bench_against_b");
  // dep: env1 seeds 1 and 2 (10 against 20 s, 30 against 20 s), a generated world (10 against 10).
  write_run(a, "env1", "dep", 1, 100, 10, 5);
  write_run(b, "env1", "dep", 1, 100, 20, 5);
  write_run(a, "env1", "dep", 2, 100, 30, 5);
  write_run(b, "env1", "dep", 2, 100, 20, 5);
  write_run(a, "generated-s1-a50-r1", "dep", 1, 100, 10, 5);
  write_run(b, "generated-s1-a50-r1", "dep", 1, 100, 10, 5);
  // fuel: B's run touched an obstacle and hit the time limit at lower coverage.
  write_run(a, "env1", "fuel", 1, 100, 8, 5);
  write_run(b, "env1", "fuel", 1, 200, 10, 5);
  edit_run(b, "env1-fuel-s45-seed1", "\"collisions\": 0", "\"collisions\": 1");
  edit_run(b, "env1-fuel-s45-seed1", "planner_done", "time_limit");
  edit_run(b, "env1-fuel-s45-seed1", "\"coverage_pct\": 95", "\"coverage_pct\": 90.5");
  // Without a partner.
  write_run(a, "env2", "dep", 1, 100, 10, 5);
  write_run(b, "env3", "dep", 1, 100, 10, 5);

  const std::string md = bench_against_markdown(load_bench_runs(a), load_bench_runs(b));
  EXPECT_NE(md.find("| dep | 3 | 0 / 0 | 3 / 3 | 95.00 / 95.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| fuel | 1 | 0 / 1 | 1 / 0 | 95.00 / 90.50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| all planners | 4 | 0 / 1 | 4 / 3 | 95.00 / 90.50 |"), std::string::npos) << md;
  // dep over both worlds: -10, +10 and 0 s; -50, +50 and 0 %; sd 10 s and 50 %, t(2) 4.303.
  EXPECT_NE(md.find("| all (2 worlds) | dep | Time_r | 3 | 1 / 1 / 1 | +0.00 | [-24.84, 24.84] | +0.0 | "
                    "[-124.2, 124.2] |"),
            std::string::npos)
      << md;
  // Time_f is always there: fuel's 100 against 200 s.
  EXPECT_NE(md.find("| all (2 worlds) | fuel | Time_f | 1 | 1 / 0 / 0 | -100.00 | – | -50.0 | – |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| generated (1 worlds) | dep | Time_r | 1 | 0 / 1 / 0 | +0.00 | – |"), std::string::npos)
      << md;
  // env1 alone: dep's two seeds (sd 14.14 s, t(1) 12.706), and all planners pooled there.
  EXPECT_NE(md.find("| env1 | dep | Time_r | 2 | 1 / 0 / 1 | +0.00 | [-127.06, 127.06] |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| env1 | all planners | Time_r | 3 | 2 / 0 / 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| env1 | fuel | 1 | 8.0 / 10.0 |"), std::string::npos) << md;
  EXPECT_NE(md.find("- only in A: env2, dep, seed 1"), std::string::npos) << md;
  EXPECT_NE(md.find("- only in B: env3, dep, seed 1"), std::string::npos) << md;
  EXPECT_EQ(md.find("| env2 |"), std::string::npos) << md;
}

TEST(BenchReport, ABadRunFolderIsAnErrorNamingTheFile) {
  const std::string root = test::temp_dir("bench_report_bad");
  write_run(root, "env1", "dep", 1, 100, 10, 20);
  const fs::path dir = fs::path(root) / "env1-dep-s45-seed1";
  std::ofstream(dir / "coverage.csv", std::ios::app) << "garbage\n";
  try {
    load_bench_runs(root);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("coverage.csv:4"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "metrics.json")
      << "{\"world\": \"env1\", \"planner\": \"dep\", \"time_f_s\": \"soon\"}";
  try {
    load_bench_run(dir.string());
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.json: 'time_f_s' is not a number"), std::string::npos)
        << e.what();
  }
}

TEST(BenchReport, TheSpreadOverSeedsIsTheMinimumAndMaximumOfTheCurves) {
  const std::vector<std::vector<std::pair<double, double>>> curves = {
      {{0, 0}, {1, 10}, {2, 40}, {3, 80}},  // ends at 3 s and holds 80
      {{0, 0}, {1.5, 30}, {4, 60}},
      {{0.5, 5}, {2, 20}, {5, 90}}};  // nothing before 0.5 s: 0
  const SeedSpread s = spread_over_seeds(curves, 5.0, 1.0);
  ASSERT_EQ(s.t.size(), 6u);
  // Held values per step: t=0 {0,0,0}, 1 {10,0,5}, 2 {40,30,20}, 3 {80,30,20}, 4 {80,60,20}, 5 {80,60,90}.
  const double lo[] = {0, 0, 20, 20, 20, 60}, hi[] = {0, 10, 40, 80, 80, 90},
               mean[] = {0, 5, 30, 130.0 / 3, 160.0 / 3, 230.0 / 3};
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(s.t[i], static_cast<double>(i));
    EXPECT_DOUBLE_EQ(s.lo[i], lo[i]) << i;
    EXPECT_DOUBLE_EQ(s.hi[i], hi[i]) << i;
    EXPECT_NEAR(s.mean[i], mean[i], 1e-9) << i;
  }
  EXPECT_TRUE(spread_over_seeds({}, 5.0).t.empty());
}

TEST(BenchReport, TheMedianCoverageRunIsTheMiddleSeed) {
  BenchRun a, b, c, d;
  a.seed = 1, a.coverage_pct = 90;
  b.seed = 2, b.coverage_pct = 70;
  c.seed = 3, c.coverage_pct = 80;
  d.seed = 4, d.coverage_pct = 95;
  EXPECT_EQ(median_coverage_run({&a, &b, &c}), &c);
  EXPECT_EQ(median_coverage_run({&a, &b, &c, &d}), &c);  // the lower middle of four
  EXPECT_EQ(median_coverage_run({&d}), &d);
  EXPECT_EQ(median_coverage_run({}), nullptr);
}

void write_picture(const std::string& path, int w, int h, Rgb fill) { write_png(Image(w, h, fill), path); }

TEST(BenchReport, MontageTilesEveryPictureAndReportsAMissingOne) {
  const std::string dir = test::temp_dir("montage");
  fs::create_directories(dir);
  write_picture(dir + "/a.png", 800, 400, {250, 0, 0});
  write_picture(dir + "/b.png", 400, 400, {0, 0, 250});
  { std::ofstream(dir + "/broken.png") << "not a png"; }
  MontageOptions o;
  o.tile_width = 200;
  o.columns = 2;
  const Montage m = render_montage(
      {{dir + "/a.png", "a"}, {dir + "/b.png", "b"}, {dir + "/none.png", "c"}, {dir + "/broken.png", "d"}},
      o);
  ASSERT_EQ(m.missing.size(), 2u);
  EXPECT_NE(m.missing[0].find("none.png: no such file"), std::string::npos);
  EXPECT_NE(m.missing[1].find("broken.png: not a readable picture"), std::string::npos);
  // Two columns of 200 px tiles, two rows; tiles 100 px high (the first picture's aspect).
  EXPECT_GT(m.image.width, 400);
  EXPECT_LT(m.image.width, 460);
  EXPECT_GT(m.image.height, 200);
  EXPECT_LT(m.image.height, 320);
  int red = 0, blue = 0;
  for (int y = 0; y < m.image.height; ++y)
    for (int x = 0; x < m.image.width; ++x) {
      const Rgb p = m.image.at(x, y);
      red += p.r > 230 && p.g < 20 && p.b < 20;
      blue += p.b > 230 && p.r < 20 && p.g < 20;
    }
  EXPECT_GT(red, 190 * 90);  // a scaled to 200 x 100
  EXPECT_GT(blue, 95 * 95);  // b fitted into 100 x 100
  EXPECT_LT(blue, 105 * 105);
}

TEST(BenchReport, MapMontageAndBandsFromRunFolders) {
  const std::string root = test::temp_dir("bench_maps");
  write_run(root, "env1", "dep", 1, 100, 10, 30);
  write_run(root, "env1", "dep", 2, 120, 20, 50);
  write_run(root, "env1", "fuel", 1, 90, 15, 40);
  write_picture(root + "/env1-dep-s45-seed1/map.png", 300, 200, {10, 200, 10});
  write_picture(root + "/env1-dep-s45-seed2/map.png", 300, 200, {10, 200, 10});
  // fuel's run folder has no map.png.
  const auto runs = load_bench_runs(root);
  std::vector<std::string> missing;
  const auto maps = write_bench_montages(runs, root, {}, &missing);
  ASSERT_EQ(maps.size(), 1u);
  EXPECT_EQ(fs::path(maps[0]).filename(), "maps_env1.png");
  EXPECT_GT(fs::file_size(maps[0]), 1000u);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_NE(missing[0].find("env1-fuel-s45-seed1/map.png"), std::string::npos);
  const auto plots = write_bench_plots(runs, root);
  ASSERT_EQ(plots.size(), 1u);
  EXPECT_TRUE(fs::exists(root + "/coverage_env1.png"));
}

}  // namespace
}  // namespace semx::evaluator
