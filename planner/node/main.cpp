// semx-planner: the exploration planner (DEP with semantic reward, or the DEP/NBV/AEP baselines,
// or the known-map oracle that reads the world's ground truth) as an LCM process (docs/planner.md).
#include <iostream>

#include "planner_node.hpp"
#ifdef SEMX_PLANNER_WITH_TRUTH
#include "ground_truth_map.hpp"
#endif
#include "semx/runtime/config.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx::runtime;

int main(int argc, char** argv) {
  return run_main("semx-planner", [&] {
    NodeFlags flags("planner");
    std::string config_file, planner, world;
    std::vector<std::string> overrides;
    int64_t seed = -1, samples = 0;
    ArgParser p(
        "semx-planner",
        "Plans exploration goals on the mapper's map: publishes PLAN_PATH, ROADMAP and PLANNER_STATUS.");
    flags.add_to(p);
    p.option("config", "FILE", "planner YAML (default: built-in defaults, docs/planner.md)", &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set gain.min_gain=30", &overrides)
        .option("planner", "NAME",
                "semantic-dep (default), dep, nbv, aep, fuel, or oracle: the known-map reference, which reads the "
                "world's ground truth (--world) and cheats (= --set planner=NAME)",
                &planner)
        .option("world", "FILE",
                "the world (env1, env2, env3 or a file) whose ground truth the oracle reads; only the oracle "
                "opens it, the other planners never do",
                &world)
        .option("seed", "N", "random seed (= --set seed=N)", &seed)
        .option("samples", "N", "sampling density (= --set sampling.samples=N)", &samples);
    if (!p.parse(argc, argv)) return 0;
    if (!planner.empty()) overrides.push_back("planner=" + planner);
    if (seed >= 0) overrides.push_back("seed=" + std::to_string(seed));
    if (samples != 0) overrides.push_back("sampling.samples=" + std::to_string(samples));
    const auto config = load_config<semx::planner::PlannerConfig>(config_file, overrides);
    std::shared_ptr<const semx::planner::TruthMap> truth;
    if (config.kind() == semx::planner::PlannerKind::kOracle) {
      if (world.empty())
        throw ArgError("--planner oracle needs --world FILE: it reads that world's ground truth");
#ifdef SEMX_PLANNER_WITH_TRUTH
      try {
        // The evaluator's resolution (its default --resolution, the mapper's): the same T.
        truth = semx::planner::GroundTruthMap::load(world, 0.1);
      } catch (const std::exception& e) {
        throw ArgError(std::string("--world '") + world + "': " + e.what());
      }
#else
      throw ArgError("--planner oracle: this semx-planner was built without the simulator library");
#endif
    }

    semx::planner::PlannerNode node(flags.options(), config);
    if (truth) node.set_truth(truth);
    install_shutdown_handlers();
    std::cout << "semx-planner: " << config.planner << ", " << config.sampling.samples << " samples, seed "
              << config.seed << " on " << node.node().url() << "\n";
    const int rc = node.run();
    std::cout << "semx-planner: " << to_string(node.planner().state()) << ": " << node.planner().last_status().reason
              << "\n";
    // What a run that does not reproduce needs first: a map gap or a resync means lost messages.
    const auto& n = node.node().counters();
    const auto& m = node.map().counters();
    const int64_t gaps = node.map().has_mirror() ? node.map().mirror().counters().gaps : 0;
    std::cout << "semx-planner: " << node.planner().iteration() << " cycles, " << node.planner().plan_id()
              << " plans; map: " << m.updates << " updates, " << m.snapshots << " snapshots, " << m.requests
              << " requests, " << gaps << " gaps; " << n.received << " messages received, " << n.malformed
              << " malformed, " << n.dropped << " dropped\n";
    return rc;
  });
}
