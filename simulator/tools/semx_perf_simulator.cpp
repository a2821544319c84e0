// semx-perf-simulator: the simulator's speed figures, one "name: value unit" line each.
//   semx-perf-simulator [--world WORLD] [--frames N] [--seconds S]
// Single-threaded throughout, so every figure is for one core.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/runtime/executable_dir.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "semx/simulator/ray_caster.hpp"
#include "semx/simulator/simulator.hpp"

namespace sim = semx::simulator;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Camera poses the vehicle could occupy: random reachable voxel centres at random yaws.
std::vector<Eigen::Isometry3d> sample_poses(const sim::World& w, int n, uint64_t seed) {
  const sim::GroundTruth gt(w, 0.1);
  const sim::VehicleReachability vr(gt, w.start.position);
  semx::core::XoshiroRng rng(seed);
  std::vector<Eigen::Isometry3d> poses;
  const Eigen::Vector3d lo = w.bounds.min, hi = w.bounds.max;
  for (int tries = 0; static_cast<int>(poses.size()) < n && tries < 100000; ++tries) {
    const Eigen::Vector3d p(rng.uniform(lo.x(), hi.x()), rng.uniform(lo.y(), hi.y()), rng.uniform(0.6, 2.0));
    if (!vr.reachable(p)) continue;
    sim::VehicleState s;
    s.position = p;
    s.yaw = rng.uniform(-M_PI, M_PI);
    poses.push_back(s.camera_pose());
  }
  return poses;
}

// The whole simulator process in LOCKSTEP with no registered node, over loopback udpm on a port
// of its own: the figure the issue asks for (rendering, encoding and publishing every frame).
double process_realtime_factor(const std::string& world, double seconds, bool rgb) {
  const std::string dir = semx::runtime::executable_dir();
  const std::string url =
      "udpm://239.255.76.67:" + std::to_string(23000 + getpid() % 1000) + "?ttl=0&recv_buf_size=4194304";
  const std::string cmd = "'" + dir + "/semx-simulator' --world " + world + " --clock lockstep --duration " +
                          std::to_string(seconds) + " --progress 0 --quiet --lcm-url '" + url + "'" +
                          (rgb ? "" : " --no-rgb") + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  char line[1024];
  double factor = -1;
  while (std::fgets(line, sizeof line, p)) {
    const char* at = std::strstr(line, "s wall (");
    if (at) factor = std::strtod(at + 8, nullptr);
  }
  return pclose(p) == 0 ? factor : -1;
}

void print(const char* name, double value, const char* unit) {
  std::printf("%s: %.1f %s\n", name, value, unit);
}

}  // namespace

int main(int argc, char** argv) {
  std::string world_name = "env3";
  int frames = 2000;
  double sim_seconds = 60.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << "usage: semx-perf-simulator [--world WORLD] [--frames N] [--seconds S]\n"
                   "Prints rasteriser and ray-caster frame rates (640x480, depth+labels, one core)\n"
                   "for WORLD (default env3) over N frames (default 2000) from reachable poses, and\n"
                   "the Simulator's real-time factor over S simulated seconds (default 60).\n";
      return 0;
    }
    if (i + 1 >= argc) {
      std::cerr << "semx-perf-simulator: " << a << " needs a value (see --help)\n";
      return 2;
    }
    const std::string v = argv[++i];
    char* end = nullptr;
    if (a == "--world") {
      world_name = v;
    } else if (a == "--frames") {
      frames = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || frames < 1) {
        std::cerr << "semx-perf-simulator: --frames needs a positive integer\n";
        return 2;
      }
    } else if (a == "--seconds") {
      sim_seconds = std::strtod(v.c_str(), &end);
      if (*end || !(sim_seconds > 0)) {
        std::cerr << "semx-perf-simulator: --seconds needs a positive number\n";
        return 2;
      }
    } else {
      std::cerr << "semx-perf-simulator: unknown option " << a << " (see --help)\n";
      return 2;
    }
  }
  try {
    const sim::World world = sim::load_world(sim::shipped_world_path(world_name));
    const semx::runtime::PinholeCamera cam;
    const auto poses = sample_poses(world, 200, 7);
    if (poses.empty()) throw std::runtime_error("no reachable pose found");
    std::printf("world: %s (%zu solids)\n", world.name.c_str(), world.solids.size());

    sim::Rasterizer raster(world);
    sim::CameraFrame frame;
    std::printf("triangles: %zu\n", raster.mesh().triangles().size());
    for (int i = 0; i < 20; ++i)
      raster.render(cam, poses[i % poses.size()], sim::kRenderDepth | sim::kRenderLabels, frame);
    size_t drawn = 0;
    auto t0 = Clock::now();
    for (int i = 0; i < frames; ++i) {
      raster.render(cam, poses[i % poses.size()], sim::kRenderDepth | sim::kRenderLabels, frame);
      drawn += raster.last_triangles_drawn();
    }
    const double t_raster = seconds_since(t0);
    print("raster_depth_labels_fps", frames / t_raster, "frames/s");
    print("raster_triangles_drawn_mean", static_cast<double>(drawn) / frames, "triangles");
    t0 = Clock::now();
    for (int i = 0; i < frames; ++i) raster.render(cam, poses[i % poses.size()], sim::kRenderAll, frame);
    print("raster_depth_labels_rgb_fps", frames / seconds_since(t0), "frames/s");
    // What the simulator node renders: RGB as runs, which its encoder turns into the payload.
    const unsigned node_channels = sim::kRenderDepth | sim::kRenderLabels | sim::kRenderRgbRuns;
    t0 = Clock::now();
    for (int i = 0; i < frames; ++i) raster.render(cam, poses[i % poses.size()], node_channels, frame);
    print("raster_depth_labels_rgb_runs_fps", frames / seconds_since(t0), "frames/s");

    const sim::RayCaster caster(world);
    const int ray_frames = 3;
    t0 = Clock::now();
    for (int i = 0; i < ray_frames; ++i)
      caster.render(cam, poses[i % poses.size()], sim::kRenderDepth | sim::kRenderLabels, frame);
    const double t_ray = seconds_since(t0);
    print("raycast_depth_labels_fps", ray_frames / t_ray, "frames/s");
    print("raster_speedup_over_raycast", (frames / t_raster) / (ray_frames / t_ray), "x");

    // Simulator: a vehicle flying a slow circle; commands at the controller's 50 Hz.
    auto run = [&](bool render) {
      sim::SimulatorConfig cfg;
      sim::Simulator s(world, cfg);
      const int64_t end_us = static_cast<int64_t>(sim_seconds * 1e6);
      int64_t next_cmd = 0, rendered = 0;
      const auto t = Clock::now();
      while (s.time_us() < end_us) {
        if (s.time_us() >= next_cmd) {
          const double tt = s.time_us() * 1e-6;
          s.command(
              sim::ControlCommand::velocity({0.4 * std::cos(0.3 * tt), 0.4 * std::sin(0.3 * tt), 0.0}, 0.3));
          next_cmd += 20000;
        }
        const sim::StepResult r = s.step();
        if (render && r.camera_due) {
          s.render_camera(frame, sim::kRenderAll);
          ++rendered;
        }
      }
      return std::make_pair(sim_seconds / seconds_since(t), rendered);
    };
    print("sim_step_only_realtime_factor", run(false).first, "x");
    const auto [rtf, rendered] = run(true);
    print("sim_step_render_realtime_factor", rtf, "x");
    print("sim_camera_frames_rendered", static_cast<double>(rendered), "frames");
    print("lockstep_process_realtime_factor", process_realtime_factor(world_name, sim_seconds, true), "x");
    print("lockstep_process_no_rgb_realtime_factor", process_realtime_factor(world_name, sim_seconds, false),
          "x");
  } catch (const std::exception& e) {
    std::cerr << "semx-perf-simulator: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
