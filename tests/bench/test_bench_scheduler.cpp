// The bench's scheduler with a stand-in for semx-launch (a shell script writing the files a run
// leaves): semx-launch's arguments, one port per slot, the result line, FAILED runs, resume,
// Ctrl-C, the LCM log removed, and the kernel's UDP drop counter read by its header.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "semx/bench/bench_scheduler.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/monotonic_clock.hpp"

namespace semx::bench {
namespace {

namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "semx_bench_sched_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const std::string& path) {
  std::ifstream f(path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Stands in for semx-launch: writes the run folder's files from its --arg out= and planner=, and
// its --lcm-url to url.txt. Planner aep fails without metrics; planner nbv sends SIGINT to the
// bench (its parent) as Ctrl-C would, then finishes its run. With WAIT_FOR=N it waits (up to 10
// s) until N runs have written their url.txt, so that N slots are seen busy at once.
const char* kFakeLaunch = R"sh(#!/bin/sh
url=; out=; planner=
while [ $# -gt 0 ]; do
  case "$1" in
    --lcm-url) url=$2; shift 2 ;;
    --arg) case "$2" in out=*) out=${2#out=} ;; planner=*) planner=${2#planner=} ;; esac; shift 2 ;;
    *) shift ;;
  esac
done
echo "$url" > "$out/url.txt"
echo "launched"
echo log > "$out/run.lcmlog"
if [ -n "${WAIT_FOR:-}" ]; then
  i=0
  while [ "$(ls "$out"/../*/url.txt | wc -l)" -lt "$WAIT_FOR" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
fi
[ "$planner" = aep ] && exit 3
[ "$planner" = nbv ] && kill -INT "$PPID"
printf 'world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s\nenv1,%s,1,45,32.47,19.12,98.76,,0,5.9\n' "$planner" > "$out/metrics.csv"
printf '{"termination": "%s"}\n' "${TERMINATION:-planner_done}" > "$out/metrics.json"
)sh";

SchedulerOptions fake_options(const std::string& root) {
  const std::string launcher = root + "/fake-launch";
  std::ofstream(launcher) << kFakeLaunch;
  chmod(launcher.c_str(), 0755);
  SchedulerOptions o;
  o.out_dir = root + "/out";
  fs::create_directories(o.out_dir + "/runs");
  o.launcher = launcher;
  o.snmp_path = root + "/no-snmp";
  return o;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> v;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

TEST(BenchScheduler, LaunchArgumentsAndOnePortPerSlot) {
  SchedulerOptions o;
  EXPECT_EQ(slot_lcm_url(o.base_url, 0), "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(slot_lcm_url(o.base_url, 3), "udpm://239.255.76.67:7670?ttl=0&recv_buf_size=4194304");
  o.launch_args = {"semantics_config=a.yaml"};
  const BenchRun run{"env2", "dep", "30", 2, "600"};
  EXPECT_EQ(launch_argv(run, 1, "/o/runs/env2-dep-s30-seed2", o),
            (std::vector<std::string>{"demo",      "--without",
                                      "logger",    "--no-color",
                                      "--lcm-url", "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304",
                                      "--key-out", "/o/runs/env2-dep-s30-seed2/session.key",
                                      "--arg",     "world=env2",
                                      "--arg",     "planner=dep",
                                      "--arg",     "seed=2",
                                      "--arg",     "samples=30",
                                      "--arg",     "clock=lockstep",
                                      "--arg",     "time_limit=600",
                                      "--arg",     "out=/o/runs/env2-dep-s30-seed2",
                                      "--arg",     "progress=0",
                                      "--arg",     "semantics_config=a.yaml"}));
  o.keep_logs = true;  // with --logs the set's logger runs
  EXPECT_EQ(launch_argv(run, 0, "/d", o)[1], "--no-color");
}

TEST(BenchScheduler, ResultLineFromMetricsCsv) {
  const std::string header =
      "world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s,termination\n";
  EXPECT_EQ(
      result_line(3, 72, "env1-dep-s45-seed1", header + "env1,dep,1,45,32.47,19.12,98.76,5.6,0,5.94,x\n", 61),
      "[3/72] env1-dep-s45-seed1: coverage 98.8 %, Time_f 32.5 s, Time_r 5.6 s, distance 19.1 m, "
      "collisions 0, wall 6 s (61 s so far)");
  EXPECT_EQ(result_line(1, 1, "n", header + "env1,dep,1,45,120,50,80.04,,2,30.5\n", 0),
            "[1/1] n: coverage 80.0 %, Time_f 120.0 s, Time_r N/A, distance 50.0 m, collisions 2, wall 30 s "
            "(0 s so far)");
  EXPECT_FALSE(result_line(1, 1, "n", header, 0));
  EXPECT_FALSE(result_line(1, 1, "n", "", 0));
}

TEST(BenchScheduler, UdpDropsReadRcvbufErrorsByTheHeader) {
  const std::string d = temp_dir("snmp");
  std::ofstream(d + "/snmp") << "Ip: Forwarding DefaultTTL\nIp: 1 64\n"
                                "Udp: InDatagrams NoPorts InErrors OutDatagrams RcvbufErrors SndbufErrors\n"
                                "Udp: 635064952 0 307307 104921302 307307 0\n"
                                "UdpLite: InDatagrams RcvbufErrors\nUdpLite: 0 5\n";
  EXPECT_EQ(udp_rcvbuf_errors(d + "/snmp"), 307307);
  std::ofstream(d + "/reordered") << "Udp: RcvbufErrors InDatagrams\nUdp: 12 99\n";
  EXPECT_EQ(udp_rcvbuf_errors(d + "/reordered"), 12);
  std::ofstream(d + "/old-kernel") << "Udp: InDatagrams NoPorts\nUdp: 1 2\n";
  EXPECT_FALSE(udp_rcvbuf_errors(d + "/old-kernel"));
  EXPECT_FALSE(udp_rcvbuf_errors(d + "/missing"));

  fs::create_directories(d + "/run");
  EXPECT_EQ(
      udp_drop_warning(10, 13, d + "/run", "[1/2] run"),
      "[1/2] run: warning: the kernel dropped 3 UDP datagrams during the run (RcvbufErrors, machine-wide): "
      "its figures may differ from a rerun");
  EXPECT_EQ(read(d + "/run/udp_drops.txt"), "3\n");
  fs::remove(d + "/run/udp_drops.txt");
  EXPECT_FALSE(udp_drop_warning(13, 13, d + "/run", "run"));
  EXPECT_FALSE(udp_drop_warning(std::nullopt, 13, d + "/run", "run"));
  EXPECT_FALSE(udp_drop_warning(5, std::nullopt, d + "/run", "run"));
  EXPECT_FALSE(fs::exists(d + "/run/udp_drops.txt"));
  fs::remove_all(d);
}

TEST(BenchScheduler, RunsEachPlanEntryAndKeepsWhatIsDone) {
  const std::string root = temp_dir("runs");
  SchedulerOptions o = fake_options(root);
  const std::vector<BenchRun> runs = {{"env1", "dep", "45", 1, "300"}, {"env1", "aep", "45", 1, "300"}};
  std::ostringstream out;
  EXPECT_EQ(run_bench(runs, o, out, runtime::monotonic_s()), 0);
  const auto l = lines(out.str());
  ASSERT_EQ(l.size(), 2u) << out.str();
  EXPECT_EQ(
      l[0].rfind("[1/2] env1-dep-s45-seed1: coverage 98.8 %, Time_f 32.5 s, Time_r N/A, distance 19.1 m, "
                 "collisions 0, wall 6 s (",
                 0),
      0u)
      << l[0];
  const std::string dir = o.out_dir + "/runs/env1-aep-s45-seed1";
  EXPECT_EQ(l[1],
            "[2/2] env1-aep-s45-seed1: FAILED (exit 3), see " + dir + "/launch.log and " + dir + "/logs/");
  EXPECT_EQ(read(dir + "/launch.log"), "launched\n");
  EXPECT_FALSE(fs::exists(o.out_dir + "/runs/env1-dep-s45-seed1/run.lcmlog"));  // without --logs

  // Again: the finished run is kept, the failed one runs again (in a fresh folder).
  std::ofstream(dir + "/stale") << "x";
  std::ostringstream again;
  EXPECT_EQ(run_bench(runs, o, again, runtime::monotonic_s()), 0);
  EXPECT_EQ(lines(again.str())[0], "[1/2] env1-dep-s45-seed1: done before, kept");
  EXPECT_TRUE(contains(again.str(), "[2/2] env1-aep-s45-seed1: FAILED (exit 3)"));
  EXPECT_FALSE(fs::exists(dir + "/stale"));

  // With --logs the log stays.
  fs::remove_all(o.out_dir + "/runs/env1-dep-s45-seed1");
  o.keep_logs = true;
  std::ostringstream logs;
  run_bench({runs[0]}, o, logs, runtime::monotonic_s());
  EXPECT_TRUE(fs::exists(o.out_dir + "/runs/env1-dep-s45-seed1/run.lcmlog"));
  fs::remove_all(root);
}

TEST(BenchScheduler, ARunStoppedBeforeItsEndRunsAgainAndWhatItLeftIsKeptAside) {
  const std::string root = temp_dir("stopped");
  SchedulerOptions o = fake_options(root);
  const std::vector<BenchRun> runs = {{"env1", "dep", "45", 1, "300"}};
  setenv("TERMINATION", "stopped", 1);
  std::ostringstream first;
  EXPECT_EQ(run_bench(runs, o, first, runtime::monotonic_s()), 0);
  unsetenv("TERMINATION");
  const std::string dir = o.out_dir + "/runs/env1-dep-s45-seed1";
  std::ofstream(dir + "/mine") << "x";

  std::ostringstream again;
  EXPECT_EQ(run_bench(runs, o, again, runtime::monotonic_s()), 0);
  const auto l = lines(again.str());
  ASSERT_EQ(l.size(), 2u) << again.str();
  const std::string aside = o.out_dir + "/interrupted/env1-dep-s45-seed1-1";
  EXPECT_EQ(l[0],
            "[1/1] env1-dep-s45-seed1: stopped before its end last time, run again (moved to " + aside + ")");
  EXPECT_EQ(l[1].rfind("[1/1] env1-dep-s45-seed1: coverage 98.8 %", 0), 0u) << l[1];
  EXPECT_EQ(read(aside + "/mine"), "x");  // nothing the stopped run left is lost
  EXPECT_FALSE(fs::exists(dir + "/mine"));

  // Finished now: kept.
  std::ostringstream third;
  EXPECT_EQ(run_bench(runs, o, third, runtime::monotonic_s()), 0);
  EXPECT_EQ(lines(third.str())[0], "[1/1] env1-dep-s45-seed1: done before, kept");
  fs::remove_all(root);
}

TEST(BenchScheduler, SlotUrlsFollowTheBaseUrl) {
  EXPECT_EQ(slot_lcm_url("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304", 2),
            "udpm://239.255.76.67:7669?ttl=0&recv_buf_size=4194304");
  // LCM_DEFAULT_URL as docs showed it: the receive buffer the bench needs is added.
  EXPECT_EQ(slot_lcm_url("udpm://239.255.76.67:7711?ttl=0", 0),
            "udpm://239.255.76.67:7711?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(slot_lcm_url("udpm://239.255.76.68:7711", 1), "udpm://239.255.76.68:7712?recv_buf_size=4194304");
  EXPECT_EQ(slot_lcm_url("udpm://239.255.76.67:7711?recv_buf_size=8388608&ttl=0", 0, 9000),
            "udpm://239.255.76.67:9000?recv_buf_size=8388608&ttl=0");
  EXPECT_THROW(slot_lcm_url("memq://", 0), runtime::ArgError);
  EXPECT_THROW(slot_lcm_url("udpm://239.255.76.67", 0), runtime::ArgError);
  EXPECT_THROW(slot_lcm_url("udpm://239.255.76.67:76x7", 0), runtime::ArgError);
  EXPECT_THROW(slot_lcm_url("udpm://239.255.76.67:65535", 1), runtime::ArgError);
}

TEST(BenchScheduler, SlotsRunAtOnceEachOnItsPort) {
  const std::string root = temp_dir("slots");
  SchedulerOptions o = fake_options(root);
  o.slots = 2;
  setenv("WAIT_FOR", "2", 1);
  const std::vector<BenchRun> runs = {
      {"env1", "dep", "45", 1, "300"}, {"env1", "dep", "45", 2, "300"}, {"env1", "dep", "45", 3, "300"}};
  std::ostringstream out;
  EXPECT_EQ(run_bench(runs, o, out, runtime::monotonic_s()), 0);
  unsetenv("WAIT_FOR");
  EXPECT_EQ(lines(out.str()).size(), 3u) << out.str();
  EXPECT_EQ(read(o.out_dir + "/runs/env1-dep-s45-seed1/url.txt"),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304\n");
  EXPECT_EQ(read(o.out_dir + "/runs/env1-dep-s45-seed2/url.txt"),
            "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304\n");
  EXPECT_TRUE(contains(read(o.out_dir + "/runs/env1-dep-s45-seed3/url.txt"), "udpm://239.255.76.67:766"));
  fs::remove_all(root);
}

TEST(BenchScheduler, SigintStartsNoMoreRunsAndARerunContinues) {
  const std::string root = temp_dir("sigint");
  SchedulerOptions o = fake_options(root);
  signal(SIGINT, SIG_DFL);  // whatever ctest was started with
  // The first run sends SIGINT to the bench and then finishes: it gets its line, the second is
  // not started.
  const std::vector<BenchRun> runs = {{"env1", "nbv", "45", 1, "300"}, {"env1", "dep", "45", 1, "300"}};
  std::ostringstream out;
  EXPECT_EQ(run_bench(runs, o, out, runtime::monotonic_s()), 130);
  const auto l = lines(out.str());
  ASSERT_EQ(l.size(), 1u) << out.str();
  EXPECT_EQ(l[0].rfind("[1/2] env1-nbv-s45-seed1: coverage 98.8 %", 0), 0u);
  EXPECT_FALSE(fs::exists(o.out_dir + "/runs/env1-dep-s45-seed1"));

  std::ostringstream again;
  EXPECT_EQ(run_bench(runs, o, again, runtime::monotonic_s()), 0);
  const auto m = lines(again.str());
  ASSERT_EQ(m.size(), 2u) << again.str();
  EXPECT_EQ(m[0], "[1/2] env1-nbv-s45-seed1: done before, kept");
  EXPECT_EQ(m[1].rfind("[2/2] env1-dep-s45-seed1: coverage 98.8 %", 0), 0u);
  fs::remove_all(root);
}

TEST(BenchScheduler, ASigintIgnoredOnEntryStaysIgnored) {
  const std::string root = temp_dir("sigign");
  SchedulerOptions o = fake_options(root);
  signal(SIGINT, SIG_IGN);  // a bench started with & from a script
  const std::vector<BenchRun> runs = {{"env1", "nbv", "45", 1, "300"}, {"env1", "dep", "45", 1, "300"}};
  std::ostringstream out;
  EXPECT_EQ(run_bench(runs, o, out, runtime::monotonic_s()), 0);
  signal(SIGINT, SIG_DFL);
  EXPECT_EQ(lines(out.str()).size(), 2u) << out.str();
  fs::remove_all(root);
}

TEST(BenchScheduler, AMissingLauncherIsAFailedRun) {
  const std::string root = temp_dir("missing");
  SchedulerOptions o = fake_options(root);
  o.launcher = root + "/no-such-launcher";
  std::ostringstream out;
  EXPECT_EQ(run_bench({{"env1", "dep", "45", 1, "300"}}, o, out, runtime::monotonic_s()), 0);
  EXPECT_TRUE(contains(out.str(), "[1/1] env1-dep-s45-seed1: FAILED (exit 127)")) << out.str();
  EXPECT_TRUE(contains(read(o.out_dir + "/runs/env1-dep-s45-seed1/launch.log"), "cannot run"));
  fs::remove_all(root);
}

}  // namespace
}  // namespace semx::bench
