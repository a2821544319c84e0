// semx-evaluator: coverage against the world's ground truth and the paper's metrics, live, from
// the bus; writes the run folder when the run ends (docs/evaluation.md).
#include <iostream>

#include "evaluator_node.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/restart_count.hpp"
#include "semx/simulator/world.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-evaluator", [&] {
    runtime::NodeFlags flags("evaluator");
    std::string world = "env1", out, planner, state;
    int64_t seed = -1, samples = -1;
    double time_limit = 0, progress = 10, resolution = 0.1, sample_period = 1.0;
    runtime::ArgParser p(
        "semx-evaluator",
        "Measures an exploration run against the world's ground truth (coverage, Time_f, Distance,\n"
        "Time_r at 85 %, collisions), prints progress, and when the planner declares DONE, the\n"
        "simulator ends the episode or the time limit is reached, prints the metrics and writes the\n"
        "run folder (docs/evaluation.md).");
    flags.add_to(p);
    p.option("world", "FILE|NAME", "world file, or env1/env2/env3 (default env1)", &world)
        .option("out", "DIR", "run folder to write (default: none, only the table)", &out)
        .option("time-limit", "S", "end the run after S simulated seconds (default: none)", &time_limit)
        .option("planner", "NAME", "planner name recorded in the metrics (default: from PLANNER_STATUS)",
                &planner)
        .option("seed", "N", "seed recorded in the metrics", &seed)
        .option("samples", "N", "planner sampling density recorded in the metrics", &samples)
        .option("progress", "S", "simulated seconds between progress lines (0: none, default 10)", &progress)
        .option("resolution", "M",
                "voxel size to build the ground truth at before the map arrives "
                "(default 0.1; the map's own resolution wins)",
                &resolution)
        .option("sample-period", "S", "simulated seconds between coverage samples (default 1)",
                &sample_period)
        .option("state", "FILE",
                "journal of the run's state, appended every coverage sample; restarted by the launcher "
                "(SEMX_RESTART > 0), go on from it",
                &state);
    if (!p.parse(argc, argv)) return 0;
    if (time_limit < 0) throw runtime::ArgError("--time-limit must not be negative");
    if (progress < 0) throw runtime::ArgError("--progress must not be negative");
    if (!(resolution > 0)) throw runtime::ArgError("--resolution must be positive");
    if (!(sample_period > 0)) throw runtime::ArgError("--sample-period must be positive");

    const std::string path = world.find('/') == std::string::npos && world.find(".yaml") == std::string::npos
                                 ? simulator::shipped_world_path(world)
                                 : world;
    simulator::World w = simulator::load_world(path);
    evaluator::EvaluatorNodeOptions o;
    o.evaluation.info.world = w.name.empty() ? world : w.name;
    o.evaluation.info.world_path = path;
    o.evaluation.info.planner = planner;
    if (seed >= 0) o.evaluation.info.seed = seed;
    if (samples >= 0) o.evaluation.info.samples = samples;
    o.evaluation.time_limit_s = time_limit;
    o.evaluation.resolution = resolution;
    o.evaluation.metrics.sample_period_s = sample_period;
    o.out_dir = out;
    o.progress_s = progress;
    o.state_path = state;
    o.resume = !state.empty() && runtime::restart_count() > 0;

    runtime::Node node(flags.options());
    runtime::install_shutdown_handlers();
    evaluator::EvaluatorNode ev(node, std::move(w), o);
    std::cout << "semx-evaluator: world " << o.evaluation.info.world << " (" << path
              << "), |T| = " << ev.evaluation().tracker().target_count() << " voxels at "
              << ev.evaluation().tracker().resolution() << " m, on " << node.url()
              << (flags.lockstep ? " (lockstep)" : "") << std::endl;
    if (o.resume) {
      std::cout << "semx-evaluator: restart " << runtime::restart_count() << ": resumed " << ev.restored_records()
                << " records of " << state << " (t=" << ev.evaluation().metrics().now_utime() * 1e-6 << " s)"
                << std::endl;
    }
    return ev.run();
  });
}
