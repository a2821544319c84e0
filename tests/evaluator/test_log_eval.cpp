// The log evaluator on logs written here with lcm::LogFile: the same figures as the live node on
// the same stream; the world named by EPISODE_START; malformed events, corrupt and truncated
// logs; the executables' exit codes and run folder.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>

#include "evaluator_node.hpp"
#include "log_eval.hpp"
#include "scene.hpp"

namespace semx::evaluator {
namespace {

namespace fs = std::filesystem;
namespace ch = semx::channels;

void write_log(const std::string& path, const std::vector<test::SceneEvent>& events) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  int64_t n = 0;
  for (const auto& e : events) {
    lcm::LogEvent le;
    le.eventnum = n;
    le.timestamp = 1700000000000000 + 1000 * n++;  // the logger's wall clock: 1 ms apart
    le.channel = e.channel;
    le.datalen = static_cast<int32_t>(e.bytes.size());
    le.data = const_cast<uint8_t*>(e.bytes.data());
    ASSERT_EQ(log.writeEvent(&le), 0);
  }
}

RunSummary run_live(const std::vector<test::SceneEvent>& events) {
  runtime::NodeOptions no;
  no.name = "evaluator";
  no.lcm_url = "memq://";
  no.quiet = true;
  no.status_period_s = 1e6;
  no.lockstep = true;
  runtime::Node node(no);
  EvaluatorNodeOptions eo;
  eo.print = false;
  eo.progress_s = 0;
  EvaluatorNode ev(node, test::small_world(), eo);
  for (const auto& e : events) {
    if (ev.finished()) break;
    node.publish_raw(e.channel, e.bytes.data(), e.bytes.size());
    node.drain();
  }
  if (!ev.finished()) ev.finish(Termination::kStopped);
  return ev.evaluation().summary();
}

int run_command(const std::string& cmd) {
  const int rc = std::system((cmd + " >/dev/null 2>&1").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

class LogEvalTest : public ::testing::Test {
 protected:
  LogEvalTest() : dir_(test::temp_dir("log")), gt_(test::small_world(), 0.1) {
    world_file_ = test::small_world_file(dir_);
  }
  LogEvaluator evaluate(const std::string& log, double time_limit = 0) {
    LogEvalOptions o;
    o.log_path = log;
    o.world = world_file_;
    o.evaluation.time_limit_s = time_limit;
    LogEvaluator ev(o);
    ev.run();
    return ev;
  }
  std::string dir_, world_file_;
  simulator::GroundTruth gt_;
};

TEST_F(LogEvalTest, SameFiguresAsTheLiveLockstepEvaluator) {
  test::SceneOptions so;
  so.lose_seq = 3;
  so.snapshot_after_seq = 5;
  const auto events = test::make_scene(gt_, so);
  const std::string log = dir_ + "/run.lcmlog";
  write_log(log, events);
  LogEvalOptions o;
  o.log_path = log;
  o.world = world_file_;
  LogEvaluator ev(o);
  ev.run();
  const RunSummary a = ev.evaluation().summary();
  const RunSummary b = run_live(events);
  EXPECT_EQ(a.termination, "planner_done");
  EXPECT_EQ(a.termination, b.termination);
  EXPECT_DOUBLE_EQ(a.time_f_s, b.time_f_s);
  EXPECT_EQ(a.covered_voxels, b.covered_voxels);
  EXPECT_GT(a.covered_voxels, 0);
  EXPECT_EQ(a.time_r_s, b.time_r_s);
  EXPECT_DOUBLE_EQ(a.distance_m, b.distance_m);
  EXPECT_EQ(a.time_split.to_json(), b.time_split.to_json()) << "the split of a run and of its log agree";
  EXPECT_EQ(a.collisions, 1);
  EXPECT_EQ(a.collisions, b.collisions);
  EXPECT_EQ(a.info.planner, "test-planner");
  EXPECT_EQ(a.info.source, "log");
  EXPECT_EQ(a.info.world, "small");
  ASSERT_EQ(a.coverage.size(), b.coverage.size());
  for (size_t i = 0; i < a.coverage.size(); ++i) {
    EXPECT_DOUBLE_EQ(a.coverage[i].t_s, b.coverage[i].t_s);
    EXPECT_EQ(a.coverage[i].covered, b.coverage[i].covered);
  }
  const auto& r = ev.report();
  EXPECT_TRUE(r.clock);
  EXPECT_EQ(r.malformed, 0);
  EXPECT_EQ(r.map_gaps, 1);
  // The logger's clock, 1 ms per event, from the first ODOMETRY (event 1) to the one that ended it.
  EXPECT_NEAR(a.wall_s, (r.events_read - 2) * 1e-3, 1e-9);

  const std::string out = dir_ + "/folder";
  const auto written = ev.write_folder(out);
  EXPECT_EQ(written.size(), 7u);
  EXPECT_TRUE(fs::is_regular_file(out + "/map.png"));
  EXPECT_TRUE(fs::is_regular_file(out + "/time_split.png"));
  EXPECT_EQ(YAML::LoadFile(out + "/metrics.json")["source"].as<std::string>(), "log");
}

TEST_F(LogEvalTest, WithoutAClockMessagesAreTimeAndTheLimitApplies) {
  test::SceneOptions so;
  so.clock = false;
  so.done_us = -1;
  const std::string log = dir_ + "/noclock.lcmlog";
  write_log(log, test::make_scene(gt_, so));
  const LogEvaluator ev = evaluate(log, 3.0);
  const RunSummary s = ev.evaluation().summary();
  EXPECT_FALSE(ev.report().clock);
  EXPECT_EQ(s.termination, "time_limit");
  EXPECT_DOUBLE_EQ(s.time_f_s, 3.0);
  EXPECT_EQ(s.covered_voxels, test::covered_after(gt_, 12)[6]);
}

TEST_F(LogEvalTest, ALogThatEndsFirstEndsTheRun) {
  test::SceneOptions so;
  so.done_us = -1;
  so.ticks = 30;
  const std::string log = dir_ + "/short.lcmlog";
  write_log(log, test::make_scene(gt_, so));
  const RunSummary s = evaluate(log).evaluation().summary();
  EXPECT_EQ(s.termination, "log_end");
  EXPECT_DOUBLE_EQ(s.time_f_s, 2.9);
  EXPECT_FALSE(s.time_r_s);
}

TEST_F(LogEvalTest, MalformedEventsAreCountedAndSkipped) {
  auto events = test::make_scene(gt_, {});
  const auto clean = evaluate([&] {
                       write_log(dir_ + "/clean.lcmlog", events);
                       return dir_ + "/clean.lcmlog";
                     }())
                         .evaluation()
                         .summary();
  test::SceneEvent junk;
  junk.channel = ch::MAP_UPDATE;
  junk.bytes = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  events.insert(events.begin() + 5, junk);
  semx::odometry_t nan{};
  nan.utime = 50000;
  nan.position[0] = std::nan("");
  events.insert(events.begin() + 9, test::scene_event(ch::ODOMETRY, nan));
  junk.channel = ch::SIM_CLOCK;
  events.insert(events.begin() + 12, junk);
  junk.channel = "SOMETHING_ELSE";
  events.insert(events.begin() + 13, junk);
  const std::string log = dir_ + "/bad.lcmlog";
  write_log(log, events);
  const LogEvaluator ev = evaluate(log);
  EXPECT_EQ(ev.report().malformed, 3);
  EXPECT_NE(ev.report().first_error.find("MAP_UPDATE"), std::string::npos) << ev.report().first_error;
  const RunSummary s = ev.evaluation().summary();
  EXPECT_EQ(s.covered_voxels, clean.covered_voxels);
  EXPECT_DOUBLE_EQ(s.distance_m, clean.distance_m);
  EXPECT_EQ(s.time_r_s, clean.time_r_s);
}

TEST_F(LogEvalTest, CorruptAndTruncatedLogs) {
  const std::string junk = dir_ + "/junk.lcmlog";
  std::ofstream(junk) << "this is not an LCM log at all, not even close";
  try {
    evaluate(junk);
    FAIL() << "no error";
  } catch (const LogEvalError& e) {
    EXPECT_NE(std::string(e.what()).find("not an LCM log"), std::string::npos) << e.what();
  }
  EXPECT_THROW(evaluate(dir_ + "/missing.lcmlog"), LogEvalError);

  const std::string log = dir_ + "/cut.lcmlog";
  write_log(log, test::make_scene(gt_, {}));
  fs::resize_file(log, fs::file_size(log) - 7);  // lcm-logger killed while writing
  const LogEvaluator ev = evaluate(log);
  EXPECT_TRUE(ev.report().layout.truncated);
  EXPECT_GT(ev.evaluation().summary().covered_voxels, 0);
}

TEST_F(LogEvalTest, TheWorldComesFromEpisodeStart) {
  std::vector<test::SceneEvent> events;
  events.push_back(
      test::scene_event(ch::SIM_EVENT, test::sim_event(0, semx::sim_event_t::EPISODE_START, 1, "env1")));
  const std::string log = dir_ + "/env1.lcmlog";
  write_log(log, events);
  LogEvalOptions o;
  o.log_path = log;
  LogEvaluator ev(o);
  EXPECT_EQ(fs::path(ev.world_path()).filename(), "env1.yaml");
  EXPECT_EQ(ev.evaluation().options().info.world, "env1");
  const simulator::GroundTruth env1(simulator::load_world(simulator::shipped_world_path("env1")), 0.1);
  EXPECT_EQ(ev.evaluation().tracker().target_count(), static_cast<int64_t>(env1.target_count()));

  // Another world given for this log is refused, naming both, unless asked for.
  o.world = "env3";
  try {
    LogEvaluator refused(o);
    ADD_FAILURE() << "env3 accepted for a log of env1";
  } catch (const LogEvalError& e) {
    EXPECT_NE(std::string(e.what()).find("the log's world is 'env1'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not 'env3'"), std::string::npos) << e.what();
  }
  o.any_world = true;
  EXPECT_EQ(LogEvaluator(o).evaluation().options().info.world, "env3");
  o.world = "env1";  // the same world given is fine
  o.any_world = false;
  EXPECT_EQ(LogEvaluator(o).evaluation().options().info.world, "env1");
  o.world.clear();

  const std::string anonymous = dir_ + "/anon.lcmlog";
  write_log(anonymous, {test::scene_event(ch::PLANNER_STATUS, test::planner_status(0, 0))});
  o.log_path = anonymous;
  EXPECT_THROW(LogEvaluator{o}, LogEvalError);
}

TEST_F(LogEvalTest, Executables) {
  const std::string bin = SEMX_BIN_DIR;
  const std::string log = dir_ + "/exe.lcmlog";
  write_log(log, test::make_scene(gt_, {}));
  const std::string out = dir_ + "/exe_out";
  EXPECT_EQ(run_command(bin + "/semx-eval " + log + " --world " + world_file_ + " --out " + out +
                        " --planner dep --seed 2 --samples 30"),
            0);
  for (const char* f : {"metrics.json", "metrics.csv", "coverage.csv", "coverage.png", "map.png"}) {
    EXPECT_TRUE(fs::is_regular_file(fs::path(out) / f)) << f;
  }
  const YAML::Node j = YAML::LoadFile(out + "/metrics.json");
  EXPECT_EQ(j["planner"].as<std::string>(), "dep");
  EXPECT_EQ(j["seed"].as<int>(), 2);
  EXPECT_EQ(j["samples"].as<int>(), 30);
  EXPECT_DOUBLE_EQ(j["time_f_s"].as<double>(), 5.5);
  EXPECT_EQ(run_command(bin + "/semx-eval " + dir_ + "/missing.lcmlog --world " + world_file_), 1);
  EXPECT_EQ(run_command(bin + "/semx-eval " + log + " --world " + dir_ + "/nope.yaml"), 2);
  EXPECT_EQ(run_command(bin + "/semx-eval " + log + " --bogus"), 2);
  EXPECT_EQ(run_command(bin + "/semx-eval"), 2);
  EXPECT_EQ(run_command(bin + "/semx-evaluator --help"), 0);
  EXPECT_EQ(run_command(bin + "/semx-evaluator --world " + dir_ + "/nope.yaml --lcm-url memq://"), 2);
}

}  // namespace
}  // namespace semx::evaluator
