// The evaluator node over memq://: a scene of MAP_UPDATEs revealing a small world's ground truth,
// odometry, a collision and the planner's DONE; coverage rises, the figures are those computed
// from scratch, the run ends by each of its rules and the run folder is complete.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>

#include "evaluator_node.hpp"
#include "scene.hpp"
#include "semx/evaluator/run_folder.hpp"

namespace semx::evaluator {
namespace {

namespace fs = std::filesystem;

struct LiveRun {
  RunSummary summary;
  std::string dir;
  std::vector<std::string> written;
  int64_t map_resets = 0;
  runtime::NodeState state = runtime::NodeState::kStarting;
  int64_t map_gaps = 0;  // what the evaluator's end-of-run warning reports
};

LiveRun run_live(const std::string& name, const test::SceneOptions& so, bool lockstep,
                 double time_limit = 0) {
  const simulator::World world = test::small_world();
  const simulator::GroundTruth gt(world, 0.1);
  runtime::NodeOptions no;
  no.name = "evaluator";
  no.lcm_url = "memq://";
  no.quiet = true;
  no.status_period_s = 1e6;
  no.lockstep = lockstep;
  runtime::Node node(no);
  EvaluatorNodeOptions eo;
  eo.evaluation.info.world = "small";
  eo.evaluation.info.seed = 7;
  eo.evaluation.time_limit_s = time_limit;
  eo.evaluation.metrics.sample_period_s = 0.5;
  eo.out_dir = test::temp_dir(name);
  eo.progress_s = 1;
  eo.print = false;
  EvaluatorNode ev(node, world, eo);
  for (const auto& e : test::make_scene(gt, so)) {
    if (ev.finished()) break;
    node.publish_raw(e.channel, e.bytes.data(), e.bytes.size());
    node.drain();
  }
  if (!ev.finished()) ev.finish(Termination::kStopped);
  const int64_t gaps = ev.map().has_mirror() ? ev.map().mirror().counters().gaps : 0;
  return {ev.evaluation().summary(),    eo.out_dir,   ev.written(),
          ev.evaluation().map_resets(), node.state(), gaps};
}

// Time_r expected from the sweep: the first delta (0.25 s + 0.5 s k) with coverage >= 85 %,
// among the first `applied`.
std::optional<double> expected_time_r(const std::vector<int64_t>& covered, int64_t target, int applied) {
  for (int n = 1; n <= applied; ++n) {
    if (static_cast<double>(covered[n]) / static_cast<double>(target) >= 0.85) return 0.25 + 0.5 * (n - 1);
  }
  return std::nullopt;
}

class EvaluatorNodeTest : public ::testing::Test {
 protected:
  EvaluatorNodeTest() : gt_(test::small_world(), 0.1), covered_(test::covered_after(gt_, 12)) {}
  int64_t target() const { return static_cast<int64_t>(gt_.target_count()); }
  simulator::GroundTruth gt_;
  std::vector<int64_t> covered_;
};

TEST_F(EvaluatorNodeTest, LockstepRunEndsAtThePlannersDoneWithTheFolderComplete) {
  const LiveRun r = run_live("done", {}, true);
  const RunSummary& s = r.summary;
  EXPECT_EQ(s.termination, "planner_done");
  EXPECT_EQ(s.info.planner, "test-planner");
  EXPECT_DOUBLE_EQ(s.time_f_s, 5.5);
  // Ended at the tick after DONE (5.6 s): the 11 deltas stamped before it are in.
  EXPECT_EQ(s.covered_voxels, covered_[11]);
  EXPECT_EQ(s.target_voxels, target());
  EXPECT_NEAR(s.coverage_pct, 100.0 * covered_[11] / target(), 1e-9);
  EXPECT_EQ(s.time_r_s, expected_time_r(covered_, target(), 11));
  ASSERT_TRUE(s.time_r_s) << "the scene is meant to cross 85 % before DONE";
  EXPECT_NEAR(s.distance_m, 5.6 / 3.0, 1e-9);
  EXPECT_EQ(s.collisions, 1);
  EXPECT_EQ(r.state, runtime::NodeState::kDone);

  for (const char* f : {"metrics.json", "metrics.csv", "coverage.csv", "coverage.png", "map.png", "map.bt",
                        "time_split.json", "time_split.png"}) {
    EXPECT_TRUE(fs::is_regular_file(fs::path(r.dir) / f)) << f;
  }
  EXPECT_EQ(r.written.size(), 8u);
  {
    // The split accounts for every second up to Time_f.
    const YAML::Node split = YAML::LoadFile(r.dir + "/time_split.json");
    double total = 0;
    for (const auto& use : split["uses"]) total += use.second["time_s"].as<double>();
    EXPECT_NEAR(total, split["time_f_s"].as<double>(), 1e-6);
    EXPECT_NEAR(split["time_f_s"].as<double>(), 5.5, 1e-9);
  }
  {
    std::ifstream bt(r.dir + "/map.bt");
    std::string first;
    std::getline(bt, first);
    EXPECT_EQ(first, "# Octomap OcTree binary file") << "octovis reads it";
  }
  const YAML::Node j = YAML::LoadFile(r.dir + "/metrics.json");
  EXPECT_EQ(j["world"].as<std::string>(), "small");
  EXPECT_EQ(j["seed"].as<int>(), 7);
  EXPECT_TRUE(j["samples"].IsNull());
  EXPECT_DOUBLE_EQ(j["time_f_s"].as<double>(), 5.5);
  EXPECT_EQ(j["collisions"].as<int>(), 1);
  // Coverage rises over time, from 0 to the final figure.
  const auto cov = read_coverage_csv(r.dir + "/coverage.csv");
  ASSERT_GE(cov.size(), 10u);
  EXPECT_DOUBLE_EQ(cov.front().coverage_pct, 0.0);
  for (size_t i = 1; i < cov.size(); ++i) {
    EXPECT_GT(cov[i].t_s, cov[i - 1].t_s);
    EXPECT_GE(cov[i].coverage_pct, cov[i - 1].coverage_pct);
  }
  EXPECT_NEAR(cov.back().coverage_pct, s.coverage_pct, 1e-6);
  EXPECT_DOUBLE_EQ(cov.back().t_s, 5.5);
}

TEST_F(EvaluatorNodeTest, ImmediateApplyGivesTheSameFigures) {
  const LiveRun a = run_live("lock", {}, true);
  const LiveRun b = run_live("rt", {}, false);
  EXPECT_EQ(a.map_gaps, 0);
  EXPECT_EQ(b.map_gaps, 0);
  EXPECT_EQ(a.summary.covered_voxels, b.summary.covered_voxels);
  EXPECT_EQ(a.summary.time_r_s, b.summary.time_r_s);
  EXPECT_DOUBLE_EQ(a.summary.time_f_s, b.summary.time_f_s);
  EXPECT_DOUBLE_EQ(a.summary.distance_m, b.summary.distance_m);
}

TEST_F(EvaluatorNodeTest, TimeLimitWithoutAClockUsesMessageTime) {
  test::SceneOptions so;
  so.clock = false;
  so.done_us = -1;
  const LiveRun r = run_live("limit", so, false, 3.0);
  EXPECT_EQ(r.summary.termination, "time_limit");
  EXPECT_DOUBLE_EQ(r.summary.time_f_s, 3.0);
  EXPECT_EQ(r.summary.covered_voxels, covered_[6]);    // deltas at 0.25 .. 2.75 s
  EXPECT_NEAR(r.summary.distance_m, 2.9 / 3.0, 1e-9);  // the 3.0 s odometry ends the run
  ASSERT_TRUE(r.summary.time_limit_s);
  EXPECT_TRUE(fs::is_regular_file(r.dir + "/map.png"));
}

TEST_F(EvaluatorNodeTest, EpisodeEndEndsTheRunWithWhatTheMapClientHeld) {
  test::SceneOptions so;
  so.episode_end_us = 4000000;
  so.done_us = -1;
  const LiveRun r = run_live("episode", so, true);
  EXPECT_EQ(r.summary.termination, "episode_end");
  EXPECT_DOUBLE_EQ(r.summary.time_f_s, 4.0);
  EXPECT_EQ(r.summary.covered_voxels, covered_[8]);  // 0.25 .. 3.75 s, the last ones still held
  EXPECT_NEAR(r.summary.distance_m, 3.9 / 3.0, 1e-9);
}

TEST_F(EvaluatorNodeTest, RecoversFromALostDeltaThroughASnapshot) {
  test::SceneOptions so;
  so.lose_seq = 4;
  so.snapshot_after_seq = 6;
  const LiveRun r = run_live("gap", so, true);
  EXPECT_GE(r.map_resets, 1);
  EXPECT_EQ(r.map_gaps, 1);
  EXPECT_EQ(r.summary.covered_voxels, covered_[11]);
  EXPECT_EQ(r.summary.map_seq, 11);
}

TEST_F(EvaluatorNodeTest, StoppedBeforeAnythingStillWritesAFolder) {
  test::SceneOptions so;
  so.ticks = 0;
  const LiveRun r = run_live("empty", so, false);
  EXPECT_EQ(r.summary.termination, "stopped");
  EXPECT_EQ(r.summary.covered_voxels, 0);
  EXPECT_FALSE(r.summary.time_r_s);
  EXPECT_TRUE(fs::is_regular_file(r.dir + "/map.png"));
  EXPECT_TRUE(YAML::LoadFile(r.dir + "/metrics.json")["time_r_s"].IsNull());
}

}  // namespace
}  // namespace semx::evaluator
