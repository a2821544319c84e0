// semx-simulator: the simulated world, quadrotor and sensors as an LCM process.
#include <iostream>
#include <sstream>

#include "semx/runtime/bus_listeners.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/restart_count.hpp"
#include "semx/simulator/world.hpp"
#include "simulator_node.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-simulator", [&] {
    runtime::NodeFlags flags("simulator");
    std::string world = "env1", config_file, clock = "realtime", nodes, state;
    std::vector<std::string> sets;
    double speed = 1.0, max_speed = 0, duration = 0, period_ms = 10, progress = 10, ready_timeout = 30,
           foreign_hold = runtime::foreign_hold_from_env();
    bool compress = false, raw = false, no_rgb = false;
    runtime::ArgParser p(
        "semx-simulator",
        "Simulates the world, the quadrotor and its RGB-D, label and IMU sensors, and publishes\n"
        "them with SIM_CLOCK (docs/simulator.md).");
    flags.add_to(p);
    p.option("world", "FILE|NAME", "world file, or env1/env2/env3 (default env1)", &world)
        .option("config", "FILE", "simulator config YAML (docs/simulator.md)", &config_file)
        .repeated("set", "KEY=VALUE", "override a config key, e.g. --set camera.fx=400", &sets)
        .option("clock", "realtime|lockstep", "clock mode (default realtime)", &clock)
        .option("speed", "X", "realtime: simulated seconds per wall second (default 1)", &speed)
        .option("lockstep-nodes", "A,B",
                "lockstep: nodes that must ack every tick (none: as fast as possible)", &nodes)
        .option("max-speed", "X", "lockstep: at most X simulated seconds per wall second (default: no cap)",
                &max_speed)
        .option("foreign-hold", "S",
                "lockstep: wait up to S wall seconds per tick for readers of the port outside the set "
                "(a stock lcm-logger) to take what was sent (default $SEMX_FOREIGN_HOLD, else 0.1; 0: never)",
                &foreign_hold)
        .option("duration", "S", "end the episode after S simulated seconds (default: run until stopped)",
                &duration)
        .option("period-ms", "MS", "tick length in simulated ms (default 10, the odometry period)",
                &period_ms)
        .option("progress", "S", "simulated seconds between progress lines (0: none, default 10)", &progress)
        .option(
            "ready-timeout", "S",
            "wall seconds to wait for every --lockstep-nodes node's NODE_STATUS before the first tick "
            "(default 30)",
            &ready_timeout)
        .option("state", "FILE",
                "save the simulation's state here every tick; restarted by the launcher (SEMX_RESTART > 0), "
                "resume the episode from it",
                &state)
        .flag("compress", "zlib-compress every image payload (smaller logs, slower)", &compress)
        .flag("raw-images", "send every image uncompressed (default: labels and RGB run-length coded)", &raw)
        .flag("no-rgb", "do not render or publish CAMERA_RGB", &no_rgb);
    if (!p.parse(argc, argv)) return 0;
    if (clock != "realtime" && clock != "lockstep")
      throw runtime::ArgError("--clock: '" + clock + "' is not realtime or lockstep");
    if (!(period_ms > 0)) throw runtime::ArgError("--period-ms must be positive");
    if (!(speed > 0)) throw runtime::ArgError("--speed must be positive");
    if (duration < 0) throw runtime::ArgError("--duration must not be negative");
    if (!(foreign_hold >= 0)) throw runtime::ArgError("--foreign-hold must not be negative");
    if (!(ready_timeout >= 0)) throw runtime::ArgError("--ready-timeout must not be negative");

    const auto cfg = runtime::load_config<simulator::SimulatorConfig>(config_file, sets);
    const std::string path = world.find('/') == std::string::npos && world.find(".yaml") == std::string::npos
                                 ? simulator::shipped_world_path(world)
                                 : world;
    simulator::Simulator sim(simulator::load_world(path), cfg);

    simulator::SimulatorNodeOptions o;
    o.clock.mode = clock == "lockstep" ? runtime::ClockMode::kLockstep : runtime::ClockMode::kRealtime;
    o.clock.period_us = static_cast<int64_t>(period_ms * 1000.0);
    o.clock.speed = speed;
    o.clock.max_speed = max_speed;
    o.foreign_hold_s = foreign_hold;
    std::stringstream ss(nodes);
    for (std::string n; std::getline(ss, n, ',');) {
      if (!n.empty()) o.clock.lockstep_nodes.push_back(n);
    }
    o.clock.max_ticks =
        duration > 0 ? static_cast<int64_t>(duration * 1e6 / static_cast<double>(o.clock.period_us)) + 1 : -1;
    if (compress && raw) throw runtime::ArgError("--compress and --raw-images exclude each other");
    if (compress) o.depth_codec = o.label_codec = o.rgb_codec = runtime::ImageCompression::kZlib;
    if (raw) o.label_codec = o.rgb_codec = runtime::ImageCompression::kNone;
    if (no_rgb) o.render_channels = simulator::kRenderDepth | simulator::kRenderLabels;
    o.progress_every_s = progress;
    o.ready_timeout_s = ready_timeout;
    o.state_path = state;
    o.resume = !state.empty() && runtime::restart_count() > 0;

    auto node_options = flags.options();
    node_options.follow_clock = false;  // it is the clock
    runtime::Node node(node_options);
    runtime::install_shutdown_handlers();
    std::cout << "semx-simulator: world " << sim.world().name << " (" << path << "), " << clock
              << " clock on " << node.url() << "\n";
    simulator::SimulatorNode sim_node(sim, node, o);
    if (sim_node.resumed_at() >= 0) {
      std::cout << "semx-simulator: resumed from " << state << " at tick " << sim_node.resumed_at() << " (t="
                << static_cast<double>(sim.time_us()) * 1e-6 << " s, restart " << runtime::restart_count()
                << ")" << std::endl;
    }
    return sim_node.run();
  });
}
