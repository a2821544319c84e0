// semx-controller-replay: why did the controller fly a path on the fallback? Generates every
// PLAN_PATH of a run's LCM log again, offline, with the configuration given here
// (controller_replay.hpp; docs/controller.md, "Replaying a run's paths").
#include <cstdio>
#include <string>
#include <vector>

#include "controller_replay.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

using namespace semx;
using namespace semx::controller;

namespace {

const char* kind(const GenerationResult& g) {
  if (!g.ok) return "no trajectory";
  if (!g.trajectory.optimized) return "fallback";
  return g.slowed ? "slowed" : "optimised";
}

double seconds(const std::string& flag, const std::string& v, double unset) {
  if (v.empty()) return unset;
  try {
    std::size_t used = 0;
    const double s = std::stod(v, &used);
    if (used == v.size()) return s;
  } catch (const std::exception&) {
  }
  throw runtime::ArgError("--" + flag + ": '" + v + "' is not a number of seconds");
}

}  // namespace

int main(int argc, char** argv) {
  return runtime::run_main("semx-controller-replay", [&] {
    std::string log_path, config_file, from, to;
    std::vector<std::string> overrides;
    bool all = false;
    runtime::ArgParser p(
        "semx-controller-replay",
        "Generates every PLAN_PATH of a run's log again from the ODOMETRY and ESDF_LOCAL logged "
        "before it (record them: ./semx demo --arg \"log_channels=CAMERA_.*\"); prints the paths "
        "not flown optimised at full speed (--all: every path), then the counts.");
    p.positional("LOG", "an LCM log of a run (RUN/run.lcmlog)", &log_path)
        .option("config", "FILE", "controller YAML (default: built-in defaults, docs/controller.md)",
                &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set clearance.heading_repairs=0",
                  &overrides)
        .option("from", "S", "only paths sent at or after S seconds of message time", &from)
        .option("to", "S", "only paths sent before S seconds of message time", &to)
        .flag("all", "print every path, also those flown optimised at full speed", &all);
    if (!p.parse(argc, argv)) return 0;
    const auto config = runtime::load_config<ControllerConfig>(config_file, overrides);
    const PathReplay r =
        replay_paths(log_path, config, seconds("from", from, -1e300), seconds("to", to, 1e300));
    if (r.esdf_events == 0) {
      std::fprintf(stderr,
                   "semx-controller-replay: %s holds no ESDF_LOCAL (the demo leaves it out unless told)\n",
                   log_path.c_str());
      return 1;
    }
    int optimised = 0, slowed = 0, slowed_near = 0, fallbacks = 0, none = 0, repaired = 0;
    double fallback_seconds = 0.0, slowed_seconds = 0.0;
    for (const ReplayedPath& path : r.paths) {
      const GenerationResult& g = path.generation;
      repaired += g.repaired_headings;
      const bool plain = g.ok && g.trajectory.optimized && !g.slowed;
      if (plain) {
        ++optimised;
      } else if (!g.ok) {
        ++none;
      } else if (g.slowed) {
        ++slowed;
        slowed_near += g.slow_zones > 0;
        slowed_seconds += g.trajectory.duration();
      } else {
        ++fallbacks;
        fallback_seconds += g.trajectory.duration();
      }
      // The reason starts with how the path is flown ("fallback: ...", "optimised at 0.5 m/s: ...").
      if (all || !plain)
        std::printf("%.3f s path %lld, %zu waypoints, %.2f s: %s\n", path.time,
                    static_cast<long long>(path.plan_id), path.waypoints,
                    g.ok ? g.trajectory.duration() : 0.0, g.reason.empty() ? kind(g) : g.reason.c_str());
    }
    std::printf(
        "paths: %zu\noptimised: %d\nslowed: %d (%d only near where the full-speed curve failed; %.1f s of "
        "flight)\nfallbacks: %d (%.1f s of flight)\nno trajectory: %d\n"
        "repaired headings: %d\nskipped (no map or vehicle yet, or the start too far): %d\nmalformed: %d\n",
        r.paths.size(), optimised, slowed, slowed_near, slowed_seconds, fallbacks, fallback_seconds, none,
        repaired, r.skipped, r.malformed);
    if (!r.session.empty()) std::printf("%s\n", r.session.c_str());
    return 0;
  });
}
