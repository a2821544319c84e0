// semx-mapper: the occupancy map, its ESDF and the map stream as an LCM process (docs/mapper.md).
#include <cstdio>
#include <iostream>

#include "mapper_node.hpp"
#include "semx/runtime/config.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-mapper", [&] {
    runtime::NodeFlags flags("mapper");
    std::string config_file, checkpoint;
    std::vector<std::string> overrides;
    bool ignore_bad_checkpoint = false;
    runtime::ArgParser p(
        "semx-mapper",
        "Integrates CAMERA_DEPTH into a log-odds voxel map and publishes MAP_UPDATE, ESDF_LOCAL,\n"
        "MAP_SNAPSHOT and MAP_STATS on simulation time (docs/mapper.md).");
    flags.add_to(p);
    p.option("config", "FILE", "mapper YAML (default: built-in defaults, docs/mapper.md)", &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set integration.pixel_step=2",
                  &overrides)
        .option("checkpoint", "PATH",
                "checkpoint file: loaded at start when it exists, written every checkpoint.period s of "
                "simulation time and on exit (overrides checkpoint.path)",
                &checkpoint)
        .flag("ignore-bad-checkpoint", "start with an empty map when the checkpoint cannot be read",
              &ignore_bad_checkpoint);
    if (!p.parse(argc, argv)) return 0;
    const auto config = runtime::load_config<mapper::MapperConfig>(config_file, overrides);

    mapper::MapperNodeOptions o;
    o.checkpoint_path = checkpoint;
    o.ignore_bad_checkpoint = ignore_bad_checkpoint;
    o.quiet = flags.quiet;
    runtime::Node node(flags.options());
    mapper::MapperNode mapper(node, config, o);
    runtime::install_shutdown_handlers();
    char esdf[64] = "off";
    if (config.esdf.enabled) {
      const auto& w = config.esdf.window;
      std::snprintf(esdf, sizeof(esdf), "%gx%gx%g m", w[0], w[1], w[2]);
    }
    std::printf("semx-mapper: %g m voxels, %s rays, range %g m, ESDF %s, on %s\n",
                config.occupancy.resolution, mapper::to_string(config.integration.mode),
                config.integration.max_range, esdf, node.url().c_str());
    std::printf("semx-mapper: checkpoint: %s\n", mapper.startup_note().c_str());
    std::fflush(stdout);
    const int rc = mapper.run();
    const auto& c = mapper.counters();
    const int64_t frames = mapper.mapper().frames_integrated();
    std::printf(
        "semx-mapper: %lld frames integrated (%.2f ms each), %lld skipped (frame_period_s %g s), %lld "
        "rejected, %lld malformed; seq %lld; "
        "%lld ESDF recomputes (%.2f ms each); %lld snapshots, %lld checkpoints written\n",
        static_cast<long long>(frames), frames ? c.integrate_ms / static_cast<double>(frames) : 0.0,
        static_cast<long long>(c.frames_skipped), mapper.mapper().config().integration.frame_period_s,
        static_cast<long long>(c.frames_rejected), static_cast<long long>(mapper.frames_malformed()),
        static_cast<long long>(mapper.mapper().seq()), static_cast<long long>(c.esdf_recomputes),
        c.esdf_recomputes ? c.esdf_ms / static_cast<double>(c.esdf_recomputes) : 0.0,
        static_cast<long long>(c.snapshots), static_cast<long long>(c.checkpoints));
    return rc;
  });
}
