// semx-eval: the evaluator's metrics from an lcm-logger log alone (docs/evaluation.md).
#include <cstdio>
#include <iostream>

#include "log_eval.hpp"
#include "semx/evaluator/run_folder.hpp"
#include "semx/runtime/args.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-eval", [&] {
    std::string log, world, out, planner, auth_key;
    int64_t seed = -1, samples = -1;
    double time_limit = 0, resolution = 0.1, sample_period = 1.0;
    bool any_world = false;
    runtime::ArgParser p("semx-eval",
                         "Computes a run's metrics (coverage against the ground truth, Time_f, Distance,\n"
                         "Time_r at 85 %, collisions) from an lcm-logger log of it, with no network, and\n"
                         "optionally writes a run folder (docs/evaluation.md).");
    p.positional("LOG",
                 "lcm-logger log of the run (MAP_UPDATE, MAP_SNAPSHOT, ODOMETRY, SIM_EVENT, "
                 "PLANNER_STATUS, SIM_CLOCK)",
                 &log)
        .option("world", "FILE|NAME",
                "world file or env1/env2/env3 (default: the one the log's "
                "EPISODE_START names)",
                &world)
        .flag("any-world", "evaluate against --world even when the log names another world", &any_world)
        .option("auth-key", "FILE",
                "the run's key, to check every event (default: session.key beside the log, if any; "
                "else the events of the set that sent the log's first EPISODE_START)",
                &auth_key)
        .option("out", "DIR", "run folder to write (default: none, only the table)", &out)
        .option("time-limit", "S", "end the run after S simulated seconds (default: the log's end)",
                &time_limit)
        .option("planner", "NAME", "planner name recorded in the metrics (default: from PLANNER_STATUS)",
                &planner)
        .option("seed", "N", "seed recorded in the metrics", &seed)
        .option("samples", "N", "planner sampling density recorded in the metrics", &samples)
        .option("resolution", "M", "voxel size of the ground truth before the map's is known (default 0.1)",
                &resolution)
        .option("sample-period", "S", "simulated seconds between coverage samples (default 1)",
                &sample_period);
    if (!p.parse(argc, argv)) return 0;
    if (time_limit < 0) throw runtime::ArgError("--time-limit must not be negative");
    if (!(resolution > 0)) throw runtime::ArgError("--resolution must be positive");
    if (!(sample_period > 0)) throw runtime::ArgError("--sample-period must be positive");

    evaluator::LogEvalOptions o;
    o.log_path = log;
    o.world = world;
    o.any_world = any_world;
    o.auth_key_file = auth_key;
    o.evaluation.info.planner = planner;
    if (seed >= 0) o.evaluation.info.seed = seed;
    if (samples >= 0) o.evaluation.info.samples = samples;
    o.evaluation.time_limit_s = time_limit;
    o.evaluation.resolution = resolution;
    o.evaluation.metrics.sample_period_s = sample_period;
    try {
      evaluator::LogEvaluator ev(o);
      ev.run();
      const auto& r = ev.report();
      std::printf("semx-eval: %s: %lld events%s, world %s\n", log.c_str(),
                  static_cast<long long>(r.events_read),
                  r.layout.truncated ? " (the last one cut short: ignored)" : "", ev.world_path().c_str());
      for (const auto& [channel, n] : r.channels) {
        std::printf("  %-20s %lld\n", channel.c_str(), static_cast<long long>(n));
      }
      if (!r.left_out.empty()) std::printf("semx-eval: warning: %s\n", r.left_out.c_str());
      if (r.malformed > 0) {
        std::printf("semx-eval: %lld malformed events skipped (first: %s)\n",
                    static_cast<long long>(r.malformed), r.first_error.c_str());
      }
      if (r.channels.count("MAP_UPDATE") == 0 && r.channels.count("MAP_SNAPSHOT") == 0) {
        std::printf("semx-eval: warning: the log has no MAP_UPDATE or MAP_SNAPSHOT: coverage is 0\n");
      }
      const auto s = ev.evaluation().summary();
      std::printf("semx-eval: run ended (%s) at t=%.2f s\n%s", s.termination.c_str(), s.sim_s,
                  evaluator::format_metrics_table(s).c_str());
      if (!out.empty()) {
        ev.write_folder(out);
        std::printf("semx-eval: run folder %s\n", out.c_str());
      }
    } catch (const evaluator::LogEvalError& e) {
      std::cerr << "semx-eval: " << e.what() << "\n";
      return 1;
    } catch (const evaluator::RunFolderError& e) {
      std::cerr << "semx-eval: " << e.what() << "\n";
      return 1;
    }
    return 0;
  });
}
