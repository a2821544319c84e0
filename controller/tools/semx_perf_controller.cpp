// semx-perf-controller: what trajectory generation costs and how often it falls back, on random
// cluttered scenes (./semx perf controller). One 'name: value unit' line per figure.
//
// Each instance: a 10 m, 8-waypoint random walk with boxes around it (synthetic_scene.hpp, exact
// ESDF at 0.1 m), the vehicle at rest at its start. Timed on one thread with the steady clock:
// the L-BFGS optimisation alone, and the whole generation (initial guess, optimisation, time
// scaling, yaw, dense clearance check, fallback when needed).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "semx/controller/clearance.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/tracking_controller.hpp"
#include "semx/controller/trajectory_generator.hpp"
#include "semx/fixtures/synthetic_scene.hpp"
#include "semx/runtime/args.hpp"

using namespace semx::controller;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::min<double>(v.size() - 1, std::ceil(q * v.size()) - 1));
  return v[i];
}

// Tracking RMS of a trajectory on the simulator's vehicle model: first-order velocity response
// (τ = 0.3 s), acceleration limited to 3 m/s², the command applied one 10 ms tick late.
double tracking_rms(const Trajectory& traj, const TrackingConfig& cfg) {
  TrackingController tracker(cfg);
  VehicleState v;
  v.position = traj.position_at(0);
  const double dt = 0.01, tau = 0.3, a_max = 3.0;
  Eigen::Vector3d cmd = Eigen::Vector3d::Zero();
  double sum = 0;
  int n = 0;
  for (double t = 0; t < traj.duration(); t += dt) {
    const TrajectoryPoint ref = traj.sample(t);
    const double e = (ref.position - v.position).norm();
    sum += e * e;
    ++n;
    const Eigen::Vector3d next = tracker.track(ref, v).velocity;
    Eigen::Vector3d acc = (cmd - v.velocity) / tau;
    if (acc.norm() > a_max) acc *= a_max / acc.norm();
    const Eigen::Vector3d vel = v.velocity + acc * dt;
    v.position += 0.5 * (v.velocity + vel) * dt;
    v.velocity = vel;
    cmd = next;
  }
  return n ? std::sqrt(sum / n) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  return semx::runtime::run_main("semx-perf-controller", [&] {
    int instances = 200, obstacles = 40;
    bool verbose = false;
    std::string config_file;
    std::vector<std::string> overrides;
    semx::runtime::ArgParser p("semx-perf-controller",
                               "Times trajectory optimisation of 10 m, 8-waypoint paths in cluttered ESDFs.");
    p.option("instances", "N", "random scenes (default 200)", &instances)
        .option("obstacles", "N", "boxes per scene (default 40)", &obstacles)
        .flag("verbose", "print why each fallback or failure happened (stderr)", &verbose)
        .option("config", "FILE", "controller YAML (default: built-in defaults)", &config_file)
        .repeated("set", "KEY=VALUE", "override a config key, e.g. --set optimizer.max_iterations=30",
                  &overrides);
    if (!p.parse(argc, argv)) return 0;
    const auto cfg = semx::runtime::load_config<ControllerConfig>(config_file, overrides);
    const TrajectoryGenerator gen(cfg);
    const TrajectoryOptimizer opt(cfg.optimizer);

    SceneOptions so;
    so.obstacles = obstacles;
    std::vector<double> opt_ms, gen_ms, iterations, clearance_margin, rms, slowdown;
    int fallbacks = 0, failures = 0, boxes = 0;
    std::size_t cells = 0;
    for (int i = 0; i < instances; ++i) {
      const SyntheticScene scene = make_cluttered_scene(1000 + static_cast<uint64_t>(i), so);
      boxes += static_cast<int>(scene.boxes.size());
      cells += static_cast<std::size_t>(scene.field.nx()) * scene.field.ny() * scene.field.nz();
      StartState start;
      start.position = scene.path.front();
      start.yaw = scene.yaws.front();
      std::vector<double> yaws(scene.yaws);
      for (std::size_t k = 1; k < yaws.size(); ++k)
        yaws[k] = yaws[k - 1] + std::remainder(yaws[k] - yaws[k - 1], 2 * M_PI);

      PositionSpline spline = gen.initial_spline(scene.path, start, cfg.limits.max_velocity);
      auto t0 = Clock::now();
      const OptimizerReport r =
          opt.optimize(spline, scene.field, cfg.limits.max_velocity, cfg.limits.max_acceleration,
                       cfg.clearance.bound() + cfg.optimizer.target_margin);
      opt_ms.push_back(ms_since(t0));
      iterations.push_back(r.iterations);

      t0 = Clock::now();
      const GenerationResult g = gen.generate(scene.path, yaws, start, 0.0, scene.field);
      gen_ms.push_back(ms_since(t0));
      if (verbose && (!g.ok || !g.trajectory.optimized)) {
        std::fprintf(stderr, "instance %d (seed %d): %s\n", i, 1000 + i, g.reason.c_str());
      }
      if (!g.ok) {
        ++failures;
        continue;
      }
      if (!g.trajectory.optimized) ++fallbacks;
      clearance_margin.push_back(g.clearance.min_distance - cfg.clearance.bound());
      double length = 0;
      for (std::size_t k = 1; k < scene.path.size(); ++k)
        length += (scene.path[k] - scene.path[k - 1]).norm();
      slowdown.push_back(g.trajectory.duration() / (length / cfg.limits.max_velocity));
      rms.push_back(tracking_rms(g.trajectory, cfg.tracking));
    }
    const double n = std::max(1, instances);
    std::printf("instances: %d scenes\n", instances);
    std::printf("boxes_per_scene: %.1f boxes\n", boxes / n);
    std::printf("esdf_cells_per_scene: %.0f cells\n", static_cast<double>(cells) / n);
    std::printf("optimize_median: %.3f ms\n", percentile(opt_ms, 0.5));
    std::printf("optimize_p95: %.3f ms\n", percentile(opt_ms, 0.95));
    std::printf("lbfgs_iterations_median: %.0f iterations\n", percentile(iterations, 0.5));
    std::printf("generate_median: %.3f ms\n", percentile(gen_ms, 0.5));
    std::printf("generate_p95: %.3f ms\n", percentile(gen_ms, 0.95));
    std::printf("fallback_rate: %.1f %%\n", 100.0 * fallbacks / n);
    std::printf("no_trajectory_rate: %.1f %%\n", 100.0 * failures / n);
    std::printf(
        "min_clearance_above_bound: %.3f m\n",
        clearance_margin.empty() ? 0.0 : *std::min_element(clearance_margin.begin(), clearance_margin.end()));
    std::printf("duration_over_length_at_vmax_median: %.2f x\n", percentile(slowdown, 0.5));
    std::printf("tracking_rms_first_order_model_median: %.4f m\n", percentile(rms, 0.5));
    std::printf("tracking_rms_first_order_model_max: %.4f m\n", percentile(rms, 1.0));
    return 0;
  });
}
