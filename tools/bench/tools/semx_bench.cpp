// semx-bench: the paper's experiment, what ./semx bench runs (docs/evaluation.md). Checks the
// flags, prints the plan (--dry-run) or runs it with semx-launch beside this executable, and ends
// with semx-bench-report on the output folder.
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <clocale>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>

#include "semx/bench/bench_plan.hpp"
#include "semx/bench/bench_scheduler.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/executable_dir.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/monotonic_clock.hpp"

using namespace semx;
namespace fs = std::filesystem;

namespace {

std::string now_stamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  // A glob in --worlds expands in the order the shell would have listed the files.
  std::setlocale(LC_COLLATE, "");
  // Errors read "semx: bench: ...", as they did when the bench was part of ./semx.
  return runtime::run_main("semx: bench", [&] {
    const bench::BenchOptions o = bench::parse_bench_args(std::vector<std::string>(argv + 1, argv + argc));
    if (o.help) {
      std::cout << bench::bench_help();
      return 0;
    }
    bench::validate_bench_options(o);
    if (o.dry_run) {
      std::cout << bench::dry_run_text(bench::bench_runs(o));
      return 0;
    }
    const double t0 = runtime::monotonic_s();
    std::string out = o.out.empty() ? "runs/bench-" + now_stamp() : o.out;
    std::error_code ec;
    fs::create_directories(out + "/runs", ec);
    if (ec || !fs::is_directory(out + "/runs")) {
      throw runtime::ArgError("--out '" + out + "': cannot create the directory");
    }
    out = fs::canonical(out).string();
    // The generated worlds, written once per output folder (a continued bench reuses them).
    const std::string worlds_dir = out + "/worlds";
    for (const bench::GeneratedWorld& g : bench::generated_worlds_of(o)) {
      const std::string file = worlds_dir + "/" + g.name() + ".yaml";
      if (fs::exists(file)) continue;
      fs::create_directories(worlds_dir, ec);
      const std::string cmd = "'" + runtime::executable_dir() + "/semx-world' gen --seed " +
                              std::to_string(g.seed) + " --area " + std::to_string(g.area_m2) + " --rooms " +
                              std::to_string(g.rooms) + " --out '" + file + ".tmp' > /dev/null";
      if (std::system(cmd.c_str()) != 0 || std::rename((file + ".tmp").c_str(), file.c_str()) != 0) {
        throw std::runtime_error("cannot generate '" + file + "' (" + cmd + ")");
      }
    }
    const auto runs = bench::bench_runs(o, worlds_dir);

    const int jobs = bench::job_count(o);
    std::cout << "semx: bench: " << runs.size() << " runs into " << out
              << (jobs > 1 ? " (" + std::to_string(jobs) + " at a time)" : "") << std::endl;
    bench::SchedulerOptions so;
    so.out_dir = out;
    so.launcher = runtime::executable_dir() + "/semx-launch";
    so.slots = jobs;
    so.keep_logs = o.keep_logs;
    so.clock = o.clock;
    so.launch_args = o.launch_args;
    so.base_url = bench::slot_lcm_url(runtime::resolve_lcm_url(""), 0,
                                      o.base_port.empty() ? -1 : std::stoi(o.base_port));
    std::cout << "semx: bench: slot 1 on " << so.base_url << (jobs > 1 ? " (slot k on its port + k - 1)" : "")
              << std::endl;
    if (const char* snmp = std::getenv("SEMX_SNMP"); snmp && *snmp) so.snmp_path = snmp;
    if (bench::run_bench(runs, so, std::cout, t0) == 130) {
      std::cout << "semx: bench interrupted; run it again with --out " << out << " to continue" << std::endl;
      return 130;
    }
    std::cout << "semx: bench: " << runs.size() << " runs in "
              << static_cast<long long>(runtime::monotonic_s() - t0) << " s" << std::endl;
    std::fflush(stdout);
    const std::string report = runtime::executable_dir() + "/semx-bench-report";
    if (o.against.empty()) {
      execl(report.c_str(), report.c_str(), out.c_str(), static_cast<char*>(nullptr));
    } else {
      execl(report.c_str(), report.c_str(), out.c_str(), "--against", o.against.c_str(),
            static_cast<char*>(nullptr));
    }
    throw std::runtime_error("cannot run '" + report + "': " + std::strerror(errno));
  });
}
