// semx-semantics: camera frames in, semantic regions S_i = (p, l, w, r) out (docs/semantics.md).
#include <cstdio>
#include <iostream>

#include "semantics_node.hpp"
#include "semx/runtime/config.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx::runtime;

int main(int argc, char** argv) {
  return run_main("semx-semantics", [&] {
    NodeFlags flags("semantics");
    std::string config_file;
    std::vector<std::string> overrides;
    bool print = false;
    ArgParser p("semx-semantics",
                "Detects objects in CAMERA_DEPTH + CAMERA_LABELS, tracks them in 3D and publishes "
                "SEMANTIC_REGIONS.");
    flags.add_to(p);
    p.option("config", "FILE", "semantics YAML (default: built-in defaults, docs/semantics.md)", &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set tracking.min_observations=8",
                  &overrides)
        .flag("print-regions", "print the region set whenever it changes", &print);
    if (!p.parse(argc, argv)) return 0;
    const auto config = load_config<semx::semantics::SemanticsConfig>(config_file, overrides);

    semx::semantics::set_detector_threads(1);
    semx::semantics::SemanticsNode sem(flags.options(), config);
    if (print) {
      sem.on_publish([](const std::vector<semx::semantics::Region>& regions, int64_t utime, bool changed) {
        if (!changed) return;
        std::printf("t=%.2f s: %zu regions\n", utime * 1e-6, regions.size());
        for (const auto& r : regions) {
          std::printf("  %3lld %-12s (%6.2f, %6.2f, %5.2f) w %5.0f r %4.2f obs %4d seen %3.0f%%%s\n",
                      static_cast<long long>(r.id),
                      std::string(semx::runtime::class_info(r.cls).name).c_str(), r.centroid.x(),
                      r.centroid.y(), r.centroid.z(), r.weight, r.radius, r.observations,
                      100 * r.observed_fraction, r.active ? "" : " (fully observed)");
        }
        std::fflush(stdout);
      });
    }
    install_shutdown_handlers();
    std::cout << "semx-semantics: " << sem.pipeline().detector().name() << " detector, K "
              << config.tracking.min_observations << " over " << config.tracking.min_duration_s << " s, on "
              << sem.node().url() << std::endl;
    const int rc = sem.run();
    const auto& c = sem.counters();
    std::printf(
        "semx-semantics: %lld frames processed (%.2f ms each, wall), %lld skipped (frame_period_s %g s), "
        "%lld rejected, %lld incomplete\n",
        static_cast<long long>(c.frames_processed),
        c.frames_processed ? c.process_ms / static_cast<double>(c.frames_processed) : 0.0,
        static_cast<long long>(c.frames_skipped), config.detector.frame_period_s,
        static_cast<long long>(c.frames_rejected), static_cast<long long>(c.frames_incomplete));
    return rc;
  });
}
