// The main job end to end: the real process set of ./semx demo (simulator, mapper, semantics,
// planner, controller, evaluator, lcm-logger) over udpm in lockstep on env1 for a short time
// limit. Coverage must rise, nothing may collide, the run folder must be complete, no process
// may be left behind, and a second run with the same seed must give the same figures.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "process_harness.hpp"
#include "semx/runtime/lcm_url.hpp"

using namespace semx::testing;
namespace fs = std::filesystem;

namespace {

constexpr double kTimeLimit = 20.0;  // simulated s: the first views and the first flights

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct DemoRun {
  std::string dir, console;
  int exit_code = -1;
};

DemoRun run_demo(const std::string& name, int port_offset) {
  DemoRun r;
  r.dir = ::testing::TempDir() + "/semx_e2e_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(r.dir);
  const std::string out = r.dir + ".out";
  const std::string url = semx::runtime::udpm_url_for_port(test_port(port_offset));
  Process launcher({bin("semx-launch"), "demo", "--lcm-url", url, "--no-color", "--arg", "out=" + r.dir,
                    "--arg", "time_limit=" + std::to_string(kTimeLimit), "--arg", "progress=5"},
                   out);
  r.exit_code = launcher.wait(400);
  r.console = read_file(out);
  return r;
}

std::vector<std::pair<double, double>> coverage_curve(const std::string& file) {
  std::vector<std::pair<double, double>> curve;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    double t = 0, c = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf", &t, &c) == 2) curve.emplace_back(t, c);
  }
  return curve;
}

}  // namespace

TEST(EndToEnd, DemoSetExploresAndWritesTheRunFolder) {
  const DemoRun a = run_demo("a", 7);
  ASSERT_EQ(a.exit_code, 0) << a.console;

  // Nothing left running: every pid the launcher started is gone.
  const std::regex re("started \\(pid ([0-9]+)\\)");
  int started = 0;
  for (std::sregex_iterator it(a.console.begin(), a.console.end(), re), end; it != end; ++it, ++started) {
    EXPECT_FALSE(pid_alive(static_cast<pid_t>(std::stol((*it)[1].str())))) << a.console;
  }
  EXPECT_EQ(started, 7) << a.console;
  // The console shows the evaluator's progress and table, not the other processes' chatter.
  EXPECT_NE(a.console.find("semx-evaluator: t=10.0 s"), std::string::npos) << a.console;
  EXPECT_NE(a.console.find("Time_r (85 %)"), std::string::npos) << a.console;
  EXPECT_EQ(a.console.find("mapper     |"), std::string::npos) << a.console;

  for (const char* f : {"metrics.json", "metrics.csv", "coverage.csv", "coverage.png", "map.png", "map.bt",
                        "run.lcmlog", "logs/mapper.log", "logs/planner.log", "logs/simulator.log"}) {
    const fs::path p = fs::path(a.dir) / f;
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_GT(fs::file_size(p), 0u) << p;
  }
  // Every lockstep node kept its promise of quiet (the clock did not wait for it on those ticks).
  for (const auto& e : fs::directory_iterator(a.dir + "/logs")) {
    EXPECT_EQ(read_file(e.path().string()).find("before its promised quiet_until"), std::string::npos) << e.path();
  }
  const YAML::Node m = YAML::LoadFile(a.dir + "/metrics.json");
  EXPECT_EQ(m["world"].as<std::string>(), "env1");
  EXPECT_EQ(m["planner"].as<std::string>(), "semantic-dep");
  EXPECT_EQ(m["seed"].as<int>(), 1);
  EXPECT_EQ(m["samples"].as<int>(), 45);
  EXPECT_EQ(m["collisions"].as<int>(), 0);
  EXPECT_NEAR(m["time_f_s"].as<double>(), kTimeLimit, 0.5);
  EXPECT_GT(m["distance_m"].as<double>(), 1.0) << "the vehicle must have flown";
  EXPECT_GT(m["coverage_pct"].as<double>(), 50.0);
  for (const char* key : {"time_r_s", "wall_s"}) EXPECT_TRUE(m[key]) << key;

  const auto curve = coverage_curve(a.dir + "/coverage.csv");
  ASSERT_GE(curve.size(), static_cast<size_t>(kTimeLimit));
  EXPECT_LT(curve.front().second, curve.back().second) << "coverage rises";
  for (size_t i = 1; i < curve.size(); ++i) EXPECT_GE(curve[i].second, curve[i - 1].second - 1e-9);
  // Still rising after the first look around: the planner flies somewhere new.
  EXPECT_GT(curve.back().second, curve[curve.size() / 2].second);

  // Lockstep: the same seed gives the same run.
  const DemoRun b = run_demo("b", 8);
  ASSERT_EQ(b.exit_code, 0) << b.console;
  EXPECT_EQ(read_file(a.dir + "/coverage.csv"), read_file(b.dir + "/coverage.csv"));
  const YAML::Node mb = YAML::LoadFile(b.dir + "/metrics.json");
  EXPECT_EQ(m["distance_m"].as<double>(), mb["distance_m"].as<double>());
  EXPECT_EQ(m["coverage_pct"].as<double>(), mb["coverage_pct"].as<double>());
}
