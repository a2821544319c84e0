// The bench's plan: the runs in the order they start (longest time limit first, the comparison
// before the sweep), the sweep entry the comparison already runs, time limits, run names, and
// flag errors that name the flag as ./semx bench always did.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "semx/bench/bench_plan.hpp"
#include "semx/runtime/args.hpp"

namespace semx::bench {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> names(const std::vector<BenchRun>& runs) {
  std::vector<std::string> v;
  for (const auto& r : runs) v.push_back(r.name() + " " + r.time_limit);
  return v;
}

std::vector<BenchRun> plan(const std::vector<std::string>& args) {
  const BenchOptions o = parse_bench_args(args);
  validate_bench_options(o);
  return bench_runs(o);
}

// The message of the ArgError that parsing and checking `args` throws ("" if none).
std::string error_of(const std::vector<std::string>& args) {
  try {
    plan(args);
  } catch (const runtime::ArgError& e) {
    return e.what();
  }
  return "";
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "semx_bench_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// The paper's 72 runs plus the FUEL-class baseline in every world and seed and the known-map oracle
// once a world (its seeds fly the same run).
TEST(BenchPlan, DefaultIsThePapersRunsWithFuelAndOracleEnv3First) {
  const auto runs = plan({});
  ASSERT_EQ(runs.size(), 84u);
  const std::vector<std::string> first = {
      "env3-nbv-s45-seed1 900",          "env3-aep-s45-seed1 900",          "env3-dep-s45-seed1 900",
      "env3-semantic-dep-s45-seed1 900", "env3-fuel-s45-seed1 900",         "env3-oracle-s45-seed1 900",
      "env3-semantic-dep-s30-seed1 900", "env3-semantic-dep-s35-seed1 900", "env3-semantic-dep-s40-seed1 900",
      "env3-semantic-dep-s50-seed1 900", "env3-nbv-s45-seed2 900",          "env3-aep-s45-seed2 900",
      "env3-dep-s45-seed2 900",          "env3-semantic-dep-s45-seed2 900", "env3-fuel-s45-seed2 900",
      "env3-semantic-dep-s30-seed2 900"};
  const auto all = names(runs);
  EXPECT_EQ(std::vector<std::string>(all.begin(), all.begin() + 16), first);
  for (const auto& run : runs) {
    if (run.planner == "oracle") {
      EXPECT_EQ(run.seed, 1) << run.name();
    }
  }
  EXPECT_EQ(runs[28].name(), "env2-nbv-s45-seed1");
  EXPECT_EQ(runs[34].name(), "env2-semantic-dep-s25-seed1");
  EXPECT_EQ(runs[37].name(), "env2-semantic-dep-s40-seed1");
  EXPECT_EQ(runs[55].time_limit, "600");
  EXPECT_EQ(runs[56].time_limit, "300");
  EXPECT_EQ(runs.back().name(), "env1-semantic-dep-s40-seed3");
}

TEST(BenchPlan, LongestTimeLimitFirstTiesInTheOrderGiven) {
  EXPECT_EQ(names(plan({"--worlds", "env1,env2,env3", "--planners", "dep", "--seeds", "1", "--sweep", ""})),
            (std::vector<std::string>{"env3-dep-s45-seed1 900", "env2-dep-s45-seed1 600",
                                      "env1-dep-s45-seed1 300"}));
  // The limit decides, not the name; equal limits keep the order of --worlds.
  EXPECT_EQ(names(plan({"--worlds", "env3,env1", "--planners", "dep", "--seeds", "1", "--sweep", "30",
                        "--time-limits", "env1=500,env3=60"})),
            (std::vector<std::string>{"env1-dep-s45-seed1 500", "env1-semantic-dep-s30-seed1 500",
                                      "env3-dep-s45-seed1 60", "env3-semantic-dep-s30-seed1 60"}));
  EXPECT_EQ(names(plan({"--worlds", "env2,env1", "--planners", "dep", "--seeds", "1", "--sweep", "",
                        "--time-limit", "120"})),
            (std::vector<std::string>{"env2-dep-s45-seed1 120", "env1-dep-s45-seed1 120"}));
  // Numerically: 1000 before 900, 99.5 before 60.
  EXPECT_EQ(names(plan({"--worlds", "env1,env2,env3", "--planners", "dep", "--seeds", "1", "--sweep", "",
                        "--time-limits", "env1=60,env2=1000,env3=99.5"})),
            (std::vector<std::string>{"env2-dep-s45-seed1 1000", "env3-dep-s45-seed1 99.5",
                                      "env1-dep-s45-seed1 60"}));
}

TEST(BenchPlan, PerSeedTheComparisonThenTheSweep) {
  EXPECT_EQ(names(plan({"--worlds", "env1", "--planners", "dep,nbv", "--seeds", "2", "--sweep", "30,40"})),
            (std::vector<std::string>{"env1-dep-s45-seed1 300", "env1-nbv-s45-seed1 300",
                                      "env1-semantic-dep-s30-seed1 300", "env1-semantic-dep-s40-seed1 300",
                                      "env1-dep-s45-seed2 300", "env1-nbv-s45-seed2 300",
                                      "env1-semantic-dep-s30-seed2 300", "env1-semantic-dep-s40-seed2 300"}));
}

TEST(BenchPlan, TheSweepSkipsTheComparisonsDensityOnlyWhenSemanticDepIsCompared) {
  EXPECT_EQ(names(plan({"--worlds", "env3", "--planners", "semantic-dep", "--seeds", "1"})),
            (std::vector<std::string>{"env3-semantic-dep-s45-seed1 900", "env3-semantic-dep-s30-seed1 900",
                                      "env3-semantic-dep-s35-seed1 900", "env3-semantic-dep-s40-seed1 900",
                                      "env3-semantic-dep-s50-seed1 900"}));
  EXPECT_EQ(names(plan({"--worlds", "env1", "--planners", "dep", "--seeds", "1"})),
            (std::vector<std::string>{"env1-dep-s45-seed1 300", "env1-semantic-dep-s25-seed1 300",
                                      "env1-semantic-dep-s30-seed1 300", "env1-semantic-dep-s35-seed1 300",
                                      "env1-semantic-dep-s40-seed1 300", "env1-semantic-dep-s45-seed1 300"}));
  // --samples moves the skipped entry; the densities compare as text, as they name the runs.
  EXPECT_EQ(names(plan({"--worlds", "env1", "--planners", "semantic-dep", "--seeds", "1", "--sweep", "30,45",
                        "--samples", "30"})),
            (std::vector<std::string>{"env1-semantic-dep-s30-seed1 300", "env1-semantic-dep-s45-seed1 300"}));
  EXPECT_EQ(
      names(plan({"--worlds", "env1", "--planners", "semantic-dep", "--seeds", "1", "--sweep", "45",
                  "--samples", "045"})),
      (std::vector<std::string>{"env1-semantic-dep-s045-seed1 300", "env1-semantic-dep-s45-seed1 300"}));
}

TEST(BenchPlan, ThePapersSweepPerWorld) {
  EXPECT_EQ(sweep_of("paper", "env1"), "25,30,35,40,45");
  EXPECT_EQ(sweep_of("paper", "env2"), "25,30,35,40,45");
  EXPECT_EQ(sweep_of("paper", "env3"), "30,35,40,45,50");
  EXPECT_EQ(sweep_of("paper", "/w/env3.yaml"), "30,35,40,45,50");
  EXPECT_EQ(sweep_of("paper", "/w/gen.yaml"), "25,30,35,40,45,50");
  EXPECT_EQ(sweep_of("30,35", "env3"), "30,35");
  EXPECT_EQ(sweep_of("", "env3"), "");
}

TEST(BenchPlan, TimeLimitLookup) {
  const std::string def = "env1=300,env2=600,env3=900";
  EXPECT_EQ(time_limit_of(def, "env1"), "300");
  EXPECT_EQ(time_limit_of(def, "env3"), "900");
  EXPECT_EQ(time_limit_of(def, "/worlds/env2.yaml"), "600");  // by the file's name
  EXPECT_EQ(time_limit_of(def, "/worlds/gen.yaml"), "600");   // none given: 600
  EXPECT_EQ(time_limit_of("*=120", "env3"), "120");
  EXPECT_EQ(time_limit_of("env1=30,*=45", "env1"), "30");
  EXPECT_EQ(time_limit_of("env1=30,*=45", "env2"), "45");
  EXPECT_EQ(time_limit_of("env1=30,env1=40", "env1"), "40");  // the last one
  EXPECT_EQ(time_limit_of("env1=30,env1=", "env1"), "600");   // sed's last match was empty ...
  EXPECT_EQ(time_limit_of("env1=,*=50", "env1"), "50");       // ... so "*" or 600 decide
  EXPECT_EQ(time_limit_of("env1=3x,*=50", "env1"), "50");     // not digits: no match
  EXPECT_EQ(time_limit_of("env10=5", "env1"), "600");
  EXPECT_EQ(time_limit_of("env1=2.5", "env1"), "2.5");
  EXPECT_EQ(time_limit_of("gen=70", "/a/b/gen.yaml"), "70");
}

TEST(BenchPlan, RunNamesAndWorldNames) {
  EXPECT_EQ((BenchRun{"env1", "dep", "45", 2, "300"}.name()), "env1-dep-s45-seed2");
  EXPECT_EQ((BenchRun{"/w/gen.yaml", "semantic-dep", "30", 10, "600"}.name()), "gen-semantic-dep-s30-seed10");
  EXPECT_EQ(world_name("env1"), "env1");
  EXPECT_EQ(world_name("a/b/c.yaml"), "c");
  EXPECT_EQ(world_name("c.yaml.yaml"), "c.yaml");
  EXPECT_EQ(world_name(".yaml"), ".yaml");
  EXPECT_EQ(world_name("dir/x/"), "x");
  EXPECT_EQ(world_name("x.yml"), "x.yml");
}

TEST(BenchPlan, DryRunText) {
  EXPECT_EQ(dry_run_text(plan({"--worlds", "env2,env1", "--planners", "dep", "--seeds", "1", "--sweep", "",
                               "--time-limit", "120"})),
            "[1/2] env2-dep-s45-seed1: time limit 120 s\n[2/2] env1-dep-s45-seed1: time limit 120 s\n");
  EXPECT_EQ(dry_run_text({}), "");
}

TEST(BenchPlan, QuickIsEnv1OneSeedNoSweepAt120s) {
  EXPECT_EQ(names(plan({"--quick"})),
            (std::vector<std::string>{"env1-nbv-s45-seed1 120", "env1-aep-s45-seed1 120",
                                      "env1-dep-s45-seed1 120", "env1-semantic-dep-s45-seed1 120",
                                      "env1-fuel-s45-seed1 120", "env1-oracle-s45-seed1 120"}));
}

TEST(BenchPlan, FlagsApplyInOrder) {
  EXPECT_EQ(parse_bench_args({"--quick", "--worlds", "env2"}).worlds, "env2");
  EXPECT_EQ(parse_bench_args({"--worlds", "env2", "--quick"}).worlds, "env1");
  EXPECT_EQ(parse_bench_args({"--time-limits", "env1=5", "--time-limit", "7"}).time_limits, "*=7");
  EXPECT_EQ(parse_bench_args({"--time-limit", "7", "--time-limits", "env1=5"}).time_limits, "env1=5");
  EXPECT_EQ(parse_bench_args({"--sweep", ""}).sweep, "");
  const BenchOptions o = parse_bench_args({"--logs", "--dry-run", "--jobs", "2", "--out", "d", "--arg", "a=1",
                                           "--arg", "b=x=y", "--against", "base"});
  EXPECT_TRUE(o.keep_logs);
  EXPECT_TRUE(o.dry_run);
  EXPECT_EQ(job_count(o), 2);
  EXPECT_EQ(o.out, "d");
  EXPECT_EQ(o.against, "base");
  EXPECT_EQ(o.launch_args, (std::vector<std::string>{"a=1", "b=x=y"}));
  // --help ends the parsing, but only what comes after it goes unread.
  EXPECT_TRUE(parse_bench_args({"--seeds", "x", "--help", "--bogus"}).help);
  EXPECT_EQ(error_of({"--bogus", "--help"}), "unknown option '--bogus' (see ./semx bench --help)");
}

TEST(BenchPlan, FlagErrorsNameTheFlag) {
  EXPECT_EQ(error_of({"--bogus"}), "unknown option '--bogus' (see ./semx bench --help)");
  EXPECT_EQ(error_of({"--worlds=env1"}), "unknown option '--worlds=env1' (see ./semx bench --help)");
  EXPECT_EQ(error_of({"-h"}), "unknown option '-h' (see ./semx bench --help)");
  EXPECT_EQ(error_of({"--worlds"}), "--worlds needs a list");
  EXPECT_EQ(error_of({"--worlds", ""}), "--worlds needs a list");
  EXPECT_EQ(error_of({"--planners"}), "--planners needs a list");
  EXPECT_EQ(error_of({"--seeds"}), "--seeds needs a number");
  EXPECT_EQ(error_of({"--sweep"}), "--sweep needs a list (or \"\")");
  EXPECT_EQ(error_of({"--samples"}), "--samples needs a number");
  EXPECT_EQ(error_of({"--time-limits"}), "--time-limits needs WORLD=S,...");
  EXPECT_EQ(error_of({"--time-limit"}), "--time-limit needs seconds");
  EXPECT_EQ(error_of({"--out", ""}), "--out needs a directory");
  EXPECT_EQ(error_of({"--against"}), "--against needs a bench folder");
  EXPECT_EQ(error_of({"--against", "/nonexistent/bench"}),
            "--against '/nonexistent/bench': not a directory (a bench's --out folder)");
  EXPECT_EQ(error_of({"--jobs"}), "--jobs needs a number");
  EXPECT_EQ(error_of({"--arg"}), "--arg needs KEY=VALUE");
  EXPECT_EQ(error_of({"--arg", "world=env2"}),
            "--arg world=env2: the bench sets 'world' itself (use --worlds, --planners, --seeds, ...)");
  EXPECT_EQ(
      error_of({"--arg", "time_limit=5"}),
      "--arg time_limit=5: the bench sets 'time_limit' itself (use --worlds, --planners, --seeds, ...)");
  EXPECT_EQ(error_of({"--arg", "progress"}),
            "--arg progress: the bench sets 'progress' itself (use --worlds, --planners, --seeds, ...)");
  EXPECT_EQ(error_of({"--arg", "semantics_config"}), "--arg 'semantics_config': expected KEY=VALUE");
  EXPECT_EQ(error_of({"--seeds", "0"}), "--seeds '0': expected a positive integer");
  EXPECT_EQ(error_of({"--seeds", "2x"}), "--seeds '2x': expected a positive integer");
  EXPECT_EQ(error_of({"--samples", "-1"}), "--samples '-1': expected a positive integer");
  EXPECT_EQ(error_of({"--jobs", "0"}), "--jobs '0': expected a positive integer");
  // Without --jobs, one set a core (at most 8); --jobs overrides it.
  EXPECT_EQ(job_count(parse_bench_args({})), default_job_count());
  EXPECT_GE(default_job_count(), 1);
  EXPECT_LE(default_job_count(), 8);
  EXPECT_EQ(job_count(parse_bench_args({"--jobs", "3"})), 3);
  EXPECT_EQ(error_of({"--planners", "dep,foo"}), "--planners: unknown planner 'foo'");
  EXPECT_EQ(error_of({"--planners", "nbv,aep,dep,semantic-dep,fuel", "--dry-run"}), "");  // every planner known
  EXPECT_EQ(error_of({"--sweep", "30,x"}), "--sweep: 'x' is not a positive integer (or paper)");
  EXPECT_EQ(error_of({"--sweep", "0"}), "--sweep: '0' is not a positive integer (or paper)");
  EXPECT_EQ(error_of({"--worlds", "env1,/nonexistent/w.yaml"}),
            "--worlds: '/nonexistent/w.yaml' is no world file (or env1, env2, env3, generated)");
  // One message per command: the checks run in the bash bench's order.
  EXPECT_EQ(error_of({"--worlds", "/nonexistent", "--planners", "foo", "--seeds", "0"}),
            "--seeds '0': expected a positive integer");
  EXPECT_EQ(error_of({"--worlds", "/nonexistent", "--planners", "foo"}), "--planners: unknown planner 'foo'");
  // --arg is checked as it is read, before the rest.
  EXPECT_EQ(error_of({"--worlds", "/nonexistent", "--arg", "seed=7"}),
            "--arg seed=7: the bench sets 'seed' itself (use --worlds, --planners, --seeds, ...)");
  EXPECT_EQ(error_of({"--seeds", "007", "--jobs", "2"}), "");
}

TEST(BenchPlan, ListsSplitOnCommasAndBlanksAndExpandGlobs) {
  EXPECT_EQ(list_words("a,,b c\td,"), (std::vector<std::string>{"a", "b", "c", "d"}));
  EXPECT_TRUE(list_words("").empty());
  EXPECT_TRUE(list_words(", ,").empty());
  const std::string d = temp_dir("glob");
  std::ofstream(d + "/b.yaml") << "x";
  std::ofstream(d + "/a.yaml") << "x";
  EXPECT_EQ(list_words("env1," + d + "/*.yaml"),
            (std::vector<std::string>{"env1", d + "/a.yaml", d + "/b.yaml"}));
  EXPECT_EQ(list_words(d + "/*.none"), (std::vector<std::string>{d + "/*.none"}));  // no match: as given
  // A world file is a world; its name and limit come from the file name.
  EXPECT_EQ(names(plan({"--worlds", d + "/b.yaml", "--planners", "dep", "--seeds", "1", "--sweep", "",
                        "--time-limits", "b=42"})),
            (std::vector<std::string>{"b-dep-s45-seed1 42"}));
  EXPECT_EQ(error_of({"--worlds", d}),
            "--worlds: '" + d + "' is no world file (or env1, env2, env3, generated)");
  fs::remove_all(d);
}

TEST(BenchPlan, HelpIsTheBenchsUsage) {
  const std::string h = bench_help();
  EXPECT_EQ(h.rfind("usage: ./semx bench [--worlds LIST]", 0), 0u);
  EXPECT_NE(h.find("--dry-run prints the runs in the order they\nwould start"), std::string::npos);
  EXPECT_EQ(h.back(), '\n');
}

TEST(BenchPlan, GeneratedIsAFixedSetOfEightWorldsFrom50To600SquareMetres) {
  const auto& g = generated_worlds();
  ASSERT_EQ(g.size(), 8u);
  EXPECT_EQ(g.front().area_m2, 50);
  EXPECT_EQ(g.back().area_m2, 600);
  EXPECT_EQ(g.front().rooms, 1);
  EXPECT_EQ(g.back().rooms, 14);
  for (std::size_t i = 1; i < g.size(); ++i) EXPECT_GT(g[i].area_m2, g[i - 1].area_m2);
  EXPECT_EQ(g[0].name(), "generated-s1-a50-r1");

  BenchOptions o =
      parse_bench_args({"--worlds", "env1,generated", "--planners", "dep", "--seeds", "1", "--sweep", ""});
  validate_bench_options(o);
  EXPECT_EQ(generated_worlds_of(o).size(), 8u);
  const auto runs = bench_runs(o, "/out/worlds");
  ASSERT_EQ(runs.size(), 9u);
  // Longest limits first: the 600 m² world's 1500 s, ..., env1's 300 s last.
  EXPECT_EQ(runs.front().world, "/out/worlds/generated-s8-a600-r14.yaml");
  EXPECT_EQ(runs.front().time_limit, "1500");
  EXPECT_EQ(runs.back().name(), "env1-dep-s45-seed1");
  // --time-limits names a generated world, or "*" all of them.
  o.time_limits = "generated-s1-a50-r1=42,*=100";
  for (const auto& r : bench_runs(o, "w")) {
    EXPECT_EQ(r.time_limit, r.world == "w/generated-s1-a50-r1.yaml" ? "42" : "100") << r.world;
  }
  EXPECT_TRUE(generated_worlds_of(parse_bench_args({"--worlds", "env1"})).empty());
}

}  // namespace
}  // namespace semx::bench
