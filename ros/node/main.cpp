// semx-ros-bridge: semx <-> ROS 1 (docs/ros.md).
#include <iostream>

#include "bridge_node.hpp"
#include "semx/runtime/config.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx::runtime;

int main(int argc, char** argv) {
  return run_main("semx-ros-bridge", [&] {
    NodeFlags flags("ros_bridge");
    std::string config_file, mode;
    std::vector<std::string> overrides;
    ArgParser p("semx-ros-bridge",
                "Mirrors a semx set to ROS 1 (odometry, TF, camera, map, ESDF slice, roadmap, regions, path, "
                "trajectory, planner status, /clock), or feeds an external set from ROS sensors and sends its "
                "commands as MAVROS setpoints (--mode external). ROS_MASTER_URI names the master.");
    flags.add_to(p);
    p.option("config", "FILE", "bridge YAML (default: built-in defaults, ros/config/bridge.yaml)", &config_file)
        .option("mode", "MODE", "mirror | external (overrides the config's mode)", &mode)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set rates.map_hz=2", &overrides);
    if (!p.parse(argc, argv)) return 0;
    if (!mode.empty()) overrides.push_back("mode=" + mode);
    const auto config = load_config<semx::rosbridge::BridgeConfig>(config_file, overrides);

    auto options = flags.options();
    // Mirroring shows a run and changes nothing of it: a bridge that joins late or misses a frame
    // makes ROS's picture incomplete, not the run invalid (and it is not owed the set's past).
    options.observer = config.mode == semx::rosbridge::BridgeMode::kMirror;
    semx::rosbridge::BridgeNode bridge(options, config);
    install_shutdown_handlers();
    const char* master = std::getenv("ROS_MASTER_URI");
    std::cout << "semx-ros-bridge: " << semx::rosbridge::to_string(config.mode) << " mode, ROS master "
              << (master ? master : "(ROS_MASTER_URI unset: http://localhost:11311)") << ", LCM "
              << bridge.node().url() << std::endl;
    return bridge.run();
  });
}
