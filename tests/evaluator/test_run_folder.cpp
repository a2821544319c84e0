// The run folder's metric files: metrics.json keys and nulls (read back with yaml-cpp, a JSON
// reader), metrics.csv, coverage.csv round trip, the folder and its errors, the table.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/run_folder.hpp"

namespace semx::evaluator {
namespace {

namespace fs = std::filesystem;

RunSummary example(bool reached) {
  RunSummary s;
  s.info.world = "env1";
  s.info.world_path = "/x/env1.yaml";
  s.info.planner = "semantic-dep";
  s.time_f_s = 312.5;
  s.distance_m = 87.25;
  s.coverage_pct = 91.234567;
  if (reached) s.time_r_s = 201.75;
  s.collisions = 0;
  s.wall_s = 40.5;
  s.termination = "planner_done";
  s.planner_state = "DONE";
  s.planner_reason = "no \"frontier\" left, done";
  s.sim_s = 312.51;
  s.realtime_factor = 7.7;
  s.resolution_m = 0.1;
  s.target_voxels = 136813;
  s.covered_voxels = 124820;
  for (int i = 0; i <= 5; ++i) s.coverage.push_back({i * 10.0, i * 18.0, i * 2.5, i * 1000});
  return s;
}

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(RunFolder, MetricsJsonHasTheKeysAndNullTimeR) {
  RunSummary s = example(false);
  const YAML::Node j = YAML::Load(metrics_json(s));
  for (const char* key :
       {"world", "planner", "seed", "samples", "time_f_s", "distance_m", "coverage_pct", "time_r_s",
        "collisions", "wall_s", "termination", "resolution_m", "target_voxels"}) {
    EXPECT_TRUE(j[key]) << key;
  }
  EXPECT_EQ(j["world"].as<std::string>(), "env1");
  EXPECT_EQ(j["planner"].as<std::string>(), "semantic-dep");
  EXPECT_TRUE(j["seed"].IsNull());
  EXPECT_TRUE(j["samples"].IsNull());
  EXPECT_TRUE(j["time_r_s"].IsNull());
  EXPECT_TRUE(j["time_limit_s"].IsNull());
  EXPECT_DOUBLE_EQ(j["time_f_s"].as<double>(), 312.5);
  EXPECT_DOUBLE_EQ(j["distance_m"].as<double>(), 87.25);
  EXPECT_NEAR(j["coverage_pct"].as<double>(), 91.234567, 1e-9);
  EXPECT_EQ(j["collisions"].as<int>(), 0);
  EXPECT_DOUBLE_EQ(j["wall_s"].as<double>(), 40.5);
  EXPECT_EQ(j["planner_reason"].as<std::string>(), "no \"frontier\" left, done");

  s = example(true);
  s.info.seed = 3;
  s.info.samples = 40;
  s.time_limit_s = 600;
  const YAML::Node k = YAML::Load(metrics_json(s));
  EXPECT_DOUBLE_EQ(k["time_r_s"].as<double>(), 201.75);
  EXPECT_EQ(k["seed"].as<int>(), 3);
  EXPECT_EQ(k["samples"].as<int>(), 40);
  EXPECT_DOUBLE_EQ(k["time_limit_s"].as<double>(), 600);
}

TEST(RunFolder, MetricsCsvIsAHeaderAndOneRow) {
  const RunSummary s = example(false);
  const std::string header = metrics_csv_header(), row = metrics_csv_row(s);
  auto fields = [](const std::string& line) {
    int n = 1;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) ++n;
    }
    return n;
  };
  EXPECT_EQ(fields(header), fields(row));
  EXPECT_EQ(header.rfind(
                "world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s", 0),
            0u);
  EXPECT_EQ(row.rfind("env1,semantic-dep,,,312.5,87.25,91.234567,,0,40.5,planner_done,", 0), 0u) << row;
}

TEST(RunFolder, WritesTheFilesAndCoverageCsvReadsBack) {
  const std::string dir = test::temp_dir("folder") + "/a/b";
  const RunSummary s = example(true);
  const auto written = write_run_metrics(dir, s);
  ASSERT_EQ(written.size(), 4u);
  for (const char* f : {"metrics.json", "metrics.csv", "coverage.csv", "coverage.png"}) {
    EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / f)) << f;
    EXPECT_GT(fs::file_size(fs::path(dir) / f), 20u) << f;
  }
  EXPECT_EQ(slurp(dir + "/coverage.png").substr(1, 3), "PNG");
  EXPECT_FALSE(fs::exists(dir + "/metrics.json.tmp"));
  const auto back = read_coverage_csv(dir + "/coverage.csv");
  ASSERT_EQ(back.size(), s.coverage.size());
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_DOUBLE_EQ(back[i].t_s, s.coverage[i].t_s);
    EXPECT_DOUBLE_EQ(back[i].coverage_pct, s.coverage[i].coverage_pct);
    EXPECT_DOUBLE_EQ(back[i].distance_m, s.coverage[i].distance_m);
    EXPECT_EQ(back[i].covered, s.coverage[i].covered);
  }
  EXPECT_THROW(read_coverage_csv(dir + "/metrics.json"), RunFolderError);
  EXPECT_THROW(read_coverage_csv(dir + "/missing.csv"), RunFolderError);
}

TEST(RunFolder, CoverageCsvMarksTheRowsFromTime95AndTheEndGame) {
  RunSummary s = example(true);  // samples at 0, 10, ..., 50 s
  s.time_95_s = 20.0;
  s.time_settled_s = 35.5;
  std::istringstream in(coverage_csv(s));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t_s,coverage_pct,distance_m,covered_voxels,object_coverage_pct,reached_95,end_game");
  std::vector<std::string> flags;
  while (std::getline(in, line)) flags.push_back(line.substr(line.size() - 3));
  EXPECT_EQ(flags, (std::vector<std::string>{"0,0", "0,0", "1,0", "1,0", "1,1", "1,1"}));
  // Never reached, never settled (no map update): no row marked.
  s.time_95_s.reset();
  s.time_settled_s.reset();
  const std::string none = coverage_csv(s);
  EXPECT_EQ(none.find(",1\n"), std::string::npos) << none;
  EXPECT_EQ(none.find(",1,"), std::string::npos) << none;
}

TEST(RunFolder, AFolderThatCannotBeCreatedIsAnErrorNamingIt) {
  const std::string base = test::temp_dir("blocked");
  fs::create_directories(base);
  std::ofstream(base + "/file") << "x";
  try {
    write_run_metrics(base + "/file/run", example(true));
    FAIL() << "no error";
  } catch (const RunFolderError& e) {
    EXPECT_NE(std::string(e.what()).find(base + "/file/run"), std::string::npos) << e.what();
  }
}

TEST(RunFolder, TableAndProgressLine) {
  const std::string t = format_metrics_table(example(false));
  EXPECT_NE(t.find("Time_f           312.50 s"), std::string::npos) << t;
  EXPECT_NE(t.find("N/A"), std::string::npos) << t;
  EXPECT_NE(t.find("91.23 %"), std::string::npos) << t;
  EXPECT_NE(format_metrics_table(example(true)).find("201.75 s"), std::string::npos);
  EXPECT_EQ(format_progress(12.0, 34.56, 20.14, 8.123, "EXECUTING"),
            "t=12.0 s  coverage=34.6%  objects=20.1%  distance=8.12 m  planner=EXECUTING");
}

}  // namespace
}  // namespace semx::evaluator
