// semx-semantics-accuracy: the semantics pipeline on the simulator's label camera (detection and
// depth noise on) along a survey path through a world, in one process; the final regions are
// compared with the world's ground-truth objects. One 'name: value unit' line per figure
// (docs/semantics.md, "Figures").
#include <cstdio>
#include <iostream>

#include "semantics_sim.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

using namespace semx::semantics;

int main(int argc, char** argv) {
  return semx::runtime::run_main("semx-semantics-accuracy", [&] {
    AccuracyOptions opt;
    std::string config_file;
    std::vector<std::string> overrides;
    bool clean = false, verbose = false;
    int64_t seed = 1;
    semx::runtime::ArgParser p("semx-semantics-accuracy",
                               "Runs semantics on the simulator along a path through a world and scores the "
                               "regions against the ground-truth objects.");
    p.option("world", "NAME|FILE",
             "world (default env2: the env2 survey path; other worlds: turns at reachable grid points)",
             &opt.world)
        .option("seed", "N", "noise seed (default 1)", &seed)
        .option("seconds", "S", "stop after S simulated seconds (default: the whole path)", &opt.max_seconds)
        .option("match-distance", "M",
                "a region matches an object of its class within M metres (default 0.5)", &opt.match_distance)
        .flag("no-noise", "turn the detection and depth noise models off", &clean)
        .option("miss", "P", "detection noise: miss probability (default 0.1)",
                &opt.detection_noise.miss_probability)
        .option("confusion", "P", "detection noise: confusion probability (default 0.05)",
                &opt.detection_noise.confusion_probability)
        .option("spurious", "R", "detection noise: false blobs per frame (default 0.2)",
                &opt.detection_noise.spurious_rate)
        .flag("verbose", "list every region and every missed object (stderr)", &verbose)
        .option("config", "FILE", "semantics YAML (default: built-in defaults)", &config_file)
        .repeated("set", "KEY=VALUE", "override a config key", &overrides);
    if (!p.parse(argc, argv)) return 0;
    set_detector_threads(1);
    if (seed < 0) throw semx::runtime::ArgError("--seed must be non-negative");
    opt.seed = static_cast<uint64_t>(seed);
    if (clean) opt.detection_noise.enabled = opt.depth_noise.enabled = false;
    const auto config = semx::runtime::load_config<SemanticsConfig>(config_file, overrides);

    const AccuracyReport r = run_accuracy(opt, config, [&](int frame, double s, std::size_t regions) {
      if (verbose) std::fprintf(stderr, "frame %d, %.1f s: %zu regions\n", frame, s, regions);
    });

    if (verbose) {
      for (const auto& m : r.matches) {
        const auto& g = m.region;
        std::fprintf(stderr, "region %3lld %-12s at (%.2f, %.2f, %.2f) obs %4d frac %.2f %s -> %s",
                     (long long)g.id, std::string(semx::runtime::class_info(g.cls).name).c_str(),
                     g.centroid.x(), g.centroid.y(), g.centroid.z(), g.observations, g.observed_fraction,
                     g.active ? "active  " : "inactive", m.object < 0 ? "FALSE POSITIVE\n" : "");
        if (m.object >= 0) {
          std::fprintf(stderr, "%s#%d error %.3f m\n",
                       std::string(semx::runtime::class_info(r.objects[m.object].cls).name).c_str(),
                       r.objects[m.object].instance, m.error);
        }
      }
      std::vector<char> found(r.objects.size(), 0);
      for (const auto& m : r.matches) {
        if (m.object >= 0) found[m.object] = 1;
      }
      for (std::size_t o = 0; o < r.objects.size(); ++o) {
        if (found[o]) continue;
        const auto& ob = r.objects[o];
        std::fprintf(stderr, "missed %s#%d at (%.2f, %.2f, %.2f), longest view %.2f s%s\n",
                     std::string(semx::runtime::class_info(ob.cls).name).c_str(), ob.instance, ob.center.x(),
                     ob.center.y(), ob.center.z(), r.longest_view_s[o],
                     r.longest_view_s[o] >= opt.min_view_s ? " (counts for recall)" : "");
        for (const auto& t : r.final_tracks) {
          if ((t.centroid() - ob.center).norm() > 1.5) continue;
          std::fprintf(
              stderr, "  track %lld %s at (%.2f, %.2f, %.2f) size (%.2f, %.2f, %.2f) obs %d p %.2f%s%s\n",
              static_cast<long long>(t.id), std::string(semx::runtime::class_info(t.cls).name).c_str(),
              t.centroid().x(), t.centroid().y(), t.centroid().z(), t.extent().x(), t.extent().y(),
              t.extent().z(), t.observations, t.probability(), t.region ? " region" : "",
              t.confused ? " confused" : "");
        }
      }
    }

    std::printf("world: %s\n", r.world.c_str());
    std::printf("noise: %s\n", clean ? "off" : "detection + depth");
    std::printf("frames: %d frames\n", r.frames);
    std::printf("frames_processed: %d frames\n", r.frames_processed);
    std::printf("duration: %.1f s\n", r.seconds);
    std::printf("objects_in_world: %zu objects\n", r.objects.size());
    std::printf("objects_in_view: %d objects\n", r.total.objects_in_view);
    std::printf("regions: %d regions\n", r.total.regions);
    std::printf("regions_inactive: %d regions\n", r.regions_inactive);
    for (const auto& [cls, s] : r.classes) {
      const std::string name(semx::runtime::class_info(cls).name);
      std::printf("precision_%s: %.1f %% (%d/%d)\n", name.c_str(), 100 * s.precision(), s.true_regions,
                  s.regions);
      std::printf("recall_%s: %.1f %% (%d/%d)\n", name.c_str(), 100 * s.recall(), s.found, s.objects_in_view);
      std::printf("centroid_error_%s: %.3f m\n", name.c_str(), s.error_mean());
    }
    std::printf("precision: %.1f %%\n", 100 * r.total.precision());
    std::printf("recall: %.1f %%\n", 100 * r.total.recall());
    std::printf("centroid_error_mean: %.3f m\n", r.total.error_mean());
    std::printf("centroid_error_max: %.3f m\n", r.total.error_max);
    std::printf("pipeline_ms_per_frame: %.2f ms\n", r.ms_per_frame);
    return 0;
  });
}
