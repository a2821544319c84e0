// semx-controller-replay: why did the controller fly a path on the fallback? Reads a run's LCM
// log (./semx bench --logs keeps it) and generates the trajectory of every PLAN_PATH again, offline,
// from the newest odometry and ESDF logged before it, with the configuration given here: one
// line per path (how it would be flown and why), so a configuration change can be tried on the
// paths a run really sent, without flying the run again.
//
// The controller takes a path at its next tick, with the odometry of that tick; the replay uses
// the odometry logged before the path, a few milliseconds older. The lines therefore match the
// run's CONTROLLER_STATUS reasons closely but not always to the digit.
#include <lcm/lcm-cpp.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "controller_messages.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/path.hpp"
#include "semx/controller/trajectory_generator.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/config.hpp"
#include "semx/runtime/log_session.hpp"

using namespace semx;
using namespace semx::controller;

namespace {

// Decodes one event, or nothing (counted by the caller) when the bytes are not a whole message.
template <class Msg>
std::optional<Msg> decode(const uint8_t* data, std::size_t size) {
  Msg m;
  try {
    if (m.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return m;
}

const char* kind(const GenerationResult& g) {
  if (!g.ok) return "none";
  if (!g.trajectory.optimized) return "fallback";
  return g.slowed ? "slowed" : "optimised";
}

}  // namespace

int main(int argc, char** argv) {
  return runtime::run_main("semx-controller-replay", [&] {
    std::string log_path, config_file, from_s, to_s;
    std::vector<std::string> overrides;
    bool all = false;
    runtime::ArgParser p(
        "semx-controller-replay",
        "Generates every logged PLAN_PATH's trajectory again from the odometry and ESDF logged "
        "before it; prints the paths that are not flown optimised at full speed (--all: every "
        "path) and the counts.");
    p.positional("LOG", "an LCM log of a run (RUN/run.lcmlog)", &log_path)
        .option("config", "FILE", "controller YAML (default: built-in defaults, docs/controller.md)",
                &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set clearance.heading_repairs=16",
                  &overrides)
        .option("from", "S", "only paths sent at or after S seconds of message time", &from_s)
        .option("to", "S", "only paths sent before S seconds of message time", &to_s)
        .flag("all", "print every path, also those flown optimised at full speed", &all);
    if (!p.parse(argc, argv)) return 0;
    const auto config = runtime::load_config<ControllerConfig>(config_file, overrides);
    const auto seconds = [](const std::string& flag, const std::string& v, double dflt) {
      if (v.empty()) return dflt;
      try {
        std::size_t used = 0;
        const double s = std::stod(v, &used);
        if (used == v.size()) return s;
      } catch (const std::exception&) {
      }
      throw runtime::ArgError("--" + flag + ": '" + v + "' is not a number of seconds");
    };
    const double from = seconds("from", from_s, -1e300), to = seconds("to", to_s, 1e300);

    const runtime::LogLayout layout = runtime::scan_log(log_path);
    runtime::LogSession session(log_path, layout, runtime::key_beside(log_path));
    lcm::LogFile log(log_path, "r");
    if (!log.good()) throw std::runtime_error(log_path + ": lcm::LogFile cannot open it");

    const TrajectoryGenerator generator(config);
    const OutsideWindow outside =
        config.clearance.outside_is_obstacle ? OutsideWindow::kObstacle : OutsideWindow::kFree;
    std::shared_ptr<GridDistanceField> field;
    std::optional<VehicleState> vehicle;
    int paths = 0, optimised = 0, slowed = 0, fallbacks = 0, none = 0, skipped = 0, malformed = 0;
    int repaired = 0;
    double fallback_seconds = 0.0;
    for (int64_t i = 0; i < layout.events; ++i) {
      const lcm::LogEvent* e = log.readNextEvent();
      if (!e) throw std::runtime_error(log_path + ": lcm::LogFile stopped at event " + std::to_string(i));
      const auto* data = static_cast<const uint8_t*>(e->data);
      const auto size = session.payload(e->channel, data, static_cast<std::size_t>(e->datalen));
      if (!size) continue;
      if (e->channel == semx::channels::ESDF_LOCAL) {
        const auto m = decode<semx::esdf_local_t>(data, *size);
        if (!m || !accept_esdf(*m)) {
          ++malformed;
          continue;
        }
        field = std::make_shared<GridDistanceField>(to_distance_field(*m, outside));
      } else if (e->channel == semx::channels::ODOMETRY) {
        const auto m = decode<semx::odometry_t>(data, *size);
        if (!m || !accept_odometry(*m)) {
          ++malformed;
          continue;
        }
        vehicle = to_vehicle_state(*m);
      } else if (e->channel == semx::channels::PLAN_PATH) {
        const auto m = decode<semx::path_t>(data, *size);
        if (!m || !accept_path(*m)) {
          ++malformed;
          continue;
        }
        const Path path = to_path(*m);
        const double t = path.utime * 1e-6;
        if (t < from || t >= to) continue;
        if (!field || !vehicle || !check_path_start(path, vehicle->position, config.path).empty()) {
          ++skipped;  // the controller would not generate for it either
          continue;
        }
        std::vector<double> yaws;
        const auto polyline = flight_polyline(path, vehicle->position, vehicle->yaw, &yaws);
        StartState start;
        start.position = vehicle->position;
        start.velocity = vehicle->velocity;
        start.yaw = vehicle->yaw;
        const GenerationResult g = generator.generate(polyline, yaws, start, path.max_speed, *field);
        ++paths;
        repaired += g.repaired_headings;
        const bool plain = g.ok && g.trajectory.optimized && !g.slowed;
        if (plain)
          ++optimised;
        else if (!g.ok)
          ++none;
        else if (g.slowed)
          ++slowed;
        else {
          ++fallbacks;
          fallback_seconds += g.trajectory.duration();
        }
        if (all || !plain) {
          // The reason starts with how the path is flown ("fallback: ...", "optimised at 0.5 m/s: ...").
          std::printf("%.3f s path %lld, %zu waypoints, %.2f s: %s\n", t,
                      static_cast<long long>(path.plan_id), path.waypoints.size(),
                      g.ok ? g.trajectory.duration() : 0.0, g.reason.empty() ? kind(g) : g.reason.c_str());
        }
      }
    }
    std::printf(
        "paths: %d\noptimised: %d\nslowed: %d\nfallbacks: %d (%.1f s of flight)\nno trajectory: %d\n"
        "repaired headings: %d\nskipped (no map or vehicle yet, or the start too far): %d\nmalformed: %d\n",
        paths, optimised, slowed, fallbacks, fallback_seconds, none, repaired, skipped, malformed);
    if (const std::string s = session.summary(); !s.empty()) std::printf("%s\n", s.c_str());
    return 0;
  });
}
