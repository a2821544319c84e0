// semx-controller: trajectory generation with ESDF optimisation and trajectory following, as an
// LCM process (docs/controller.md).
#include <iostream>

#include "controller_node.hpp"
#include "semx/runtime/config.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx::runtime;

int main(int argc, char** argv) {
  return run_main("semx-controller", [&] {
    NodeFlags flags("controller");
    std::string config_file;
    std::vector<std::string> overrides;
    ArgParser p("semx-controller",
                "Turns PLAN_PATH into a smooth, ESDF-checked trajectory and follows it with CONTROL_CMD.");
    flags.add_to(p);
    p.option("config", "FILE", "controller YAML (default: built-in defaults, docs/controller.md)",
             &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set limits.max_velocity=0.8",
                  &overrides);
    if (!p.parse(argc, argv)) return 0;
    const auto config = load_config<semx::controller::ControllerConfig>(config_file, overrides);

    semx::controller::ControllerNode controller(flags.options(), config);
    install_shutdown_handlers();
    std::cout << "semx-controller: " << config.rate_hz << " Hz, v_max " << config.limits.max_velocity
              << " m/s on " << controller.node().url() << "\n";
    return controller.run();
  });
}
