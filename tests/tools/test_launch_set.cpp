#include <gtest/gtest.h>

#include <fstream>

#include "semx/runtime/config.hpp"
#include "semx/tools/launch_set.hpp"

using namespace semx::tools;

namespace {

std::string write_set(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& text, const std::map<std::string, std::string>& overrides = {}) {
  try {
    load_launch_set(write_set("bad.yaml", text), overrides, {{"bin", "/b"}});
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

const char* kGood = R"(name: demo
description: test set
args:
  mode: realtime
  extra: ""
processes:
  - name: clock
    command: [semx-clock, --mode, "${mode}", "${extra}", "${bin}/x"]
    ends_set: true
  - name: monitor
    command: [semx-monitor]
    restart: on-failure
    max_restarts: 2
    required: false
    start_delay: 0.5
    env: {FOO: "${mode}-bar"}
)";

}  // namespace

TEST(LaunchSet, LoadsAndSubstitutes) {
  const auto set = load_launch_set(write_set("good.yaml", kGood), {{"mode", "lockstep"}}, {{"bin", "/b"}});
  EXPECT_EQ(set.name, "demo");
  ASSERT_EQ(set.processes.size(), 2u);
  EXPECT_EQ(set.processes[0].command, (std::vector<std::string>{"semx-clock", "--mode", "lockstep", "/b/x"}))
      << "empty args drop out";
  EXPECT_TRUE(set.processes[0].ends_set);
  EXPECT_TRUE(set.processes[0].required);
  EXPECT_EQ(set.processes[1].restart, RestartPolicy::kOnFailure);
  EXPECT_EQ(set.processes[1].max_restarts, 2);
  EXPECT_FALSE(set.processes[1].required);
  EXPECT_EQ(set.processes[1].start_delay_s, 0.5);
  EXPECT_EQ(set.processes[1].env.at("FOO"), "lockstep-bar");
}

TEST(LaunchSet, ErrorsNameTheProblem) {
  EXPECT_NE(error_of(kGood, {{"nope", "1"}}).find("--arg nope: the set has no such arg"), std::string::npos);
  const auto unknown_var = error_of("name: x\nprocesses:\n  - name: a\n    command: [run, \"${what}\"]\n");
  EXPECT_NE(unknown_var.find("bad.yaml:4"), std::string::npos) << unknown_var;
  EXPECT_NE(unknown_var.find("${what}"), std::string::npos) << unknown_var;
  EXPECT_NE(error_of("name: x\nprocesses:\n  - name: a\n    command: [run]\n    restart: sometimes\n")
                .find("not one of"),
            std::string::npos);
  EXPECT_NE(error_of("name: x\nprocesses:\n  - name: a\n    command: [run]\n    comand: [x]\n")
                .find("unknown key 'processes[0].comand'"),
            std::string::npos);
  EXPECT_NE(
      error_of("name: x\nprocesses:\n  - name: a\n    command: [run]\n  - name: a\n    command: [run]\n")
          .find("defined twice"),
      std::string::npos);
  EXPECT_NE(error_of("name: x\nprocesses: []\n").find("at least one process"), std::string::npos);
  EXPECT_NE(error_of("name: x\nprocesses:\n  - name: a\n").find("command"), std::string::npos);
}

TEST(LaunchSet, ExitPolicy) {
  ProcessSpec p;
  p.max_restarts = 2;
  p.restart = RestartPolicy::kOnFailure;
  EXPECT_EQ(on_process_exit(p, 1, 0, false), ExitAction::kRestart);
  EXPECT_EQ(on_process_exit(p, 1, 2, false), ExitAction::kFailSet) << "restarts used up";
  EXPECT_EQ(on_process_exit(p, 0, 0, false), ExitAction::kContinue);
  EXPECT_EQ(on_process_exit(p, 1, 0, true), ExitAction::kContinue) << "no restarts while stopping";
  p.restart = RestartPolicy::kNever;
  p.required = false;
  EXPECT_EQ(on_process_exit(p, 139, 0, false), ExitAction::kContinue);
  p.ends_set = true;
  EXPECT_EQ(on_process_exit(p, 0, 0, false), ExitAction::kEndSet);
  p.restart = RestartPolicy::kAlways;
  EXPECT_EQ(on_process_exit(p, 0, 0, false), ExitAction::kRestart);
}

TEST(LaunchSet, RestartsBackOffUpToTheCap) {
  const auto set = load_launch_set(write_set("backoff.yaml", R"(name: b
args: {out: /tmp/run}
dirs: ["${out}/state"]
processes:
  - name: a
    command: [x]
    restart: on-failure
    restart_delay: 0.5
    restart_delay_max: 3
  - name: b
    command: [y]
    restart_delay: 40
)"),
                                   {}, {});
  EXPECT_EQ(set.dirs, std::vector<std::string>{"/tmp/run/state"});
  const ProcessSpec& a = set.processes[0];
  EXPECT_DOUBLE_EQ(restart_delay(a, 1), 0.5);
  EXPECT_DOUBLE_EQ(restart_delay(a, 2), 1.0);
  EXPECT_DOUBLE_EQ(restart_delay(a, 3), 2.0);
  EXPECT_DOUBLE_EQ(restart_delay(a, 4), 3.0) << "capped";
  EXPECT_DOUBLE_EQ(restart_delay(a, 1000), 3.0);
  // A first delay beyond the default cap raises the cap to it: it never waits less than asked.
  EXPECT_DOUBLE_EQ(restart_delay(set.processes[1], 1), 40.0);
  EXPECT_DOUBLE_EQ(restart_delay(set.processes[1], 5), 40.0);
  EXPECT_NE(error_of("name: x\nprocesses:\n  - name: a\n    command: [x]\n    restart_delay: 2\n"
                     "    restart_delay_max: 1\n")
                .find("restart_delay_max"),
            std::string::npos);
}

TEST(LaunchSet, SubstituteHandlesEdges) {
  EXPECT_EQ(substitute("a${x}b${x}", {{"x", "1"}}), "a1b1");
  EXPECT_EQ(substitute("plain", {}), "plain");
  EXPECT_THROW(substitute("${open", {}), std::runtime_error);
}
