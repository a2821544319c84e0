// semx-perf-semantics: what one 640x480 frame costs the semantics pipeline on one core
// (./semx perf semantics). Frames come from the simulator's label camera (detection and depth
// noise on) along env2's survey path, so the tracker sees a realistic, growing set of objects;
// rendering is not timed. Wall time per stage (steady clock) and the thread's CPU time per frame
// (what the frame cost the core even when other work shares the machine). One 'name: value unit'
// line per figure.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "semantics_messages.hpp"
#include "semantics_sim.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"
#include "semx/semantics/pipeline.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "simulator_messages.hpp"

using namespace semx::semantics;
using Clock = std::chrono::steady_clock;

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::min<double>(v.size() - 1, std::ceil(q * v.size()) - 1));
  return v[i];
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / v.size();
}

// CPU time of this thread: what the frame cost the core, whatever else the machine was doing.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  return semx::runtime::run_main("semx-perf-semantics", [&] {
    int frames = 1500;
    std::string config_file;
    std::vector<std::string> overrides;
    semx::runtime::ArgParser p("semx-perf-semantics",
                               "Times the semantics pipeline per 640x480 frame along env2's survey path.");
    p.option("frames", "N", "frames to time (default 1500, 50 s of camera)", &frames)
        .option("config", "FILE", "semantics YAML (default: built-in defaults)", &config_file)
        .repeated("set", "KEY=VALUE", "override a config key", &overrides);
    if (!p.parse(argc, argv)) return 0;
    set_detector_threads(1);
    if (frames <= 0) throw semx::runtime::ArgError("--frames must be positive");
    const auto config = semx::runtime::load_config<SemanticsConfig>(config_file, overrides);

    using namespace semx::simulator;
    const World world = load_world(shipped_world_path("env2"));
    Rasterizer raster(world);
    const semx::runtime::PinholeCamera camera;
    const auto poses = sample_path(env2_survey_path(), world.start.yaw, 0.5, 0.6, 30.0);
    DetectionNoiseConfig detection;
    detection.enabled = true;
    DepthNoiseConfig depth;
    depth.enabled = true;

    SemanticPipeline pipeline(config);
    CameraFrame frame;
    std::vector<double> total, cpu, detect, lift, track, decode;
    std::size_t detections = 0;
    for (int k = 0; k < frames; ++k) {
      const PathPose& pose = poses[static_cast<std::size_t>(k) % poses.size()];
      VehicleState state;
      state.position = pose.position;
      state.yaw = pose.yaw;
      raster.render(camera, state.camera_pose(), kRenderDepth | kRenderLabels, frame);
      frame.utime = static_cast<int64_t>(k) * 33333;
      frame.frame_id = k;
      apply_depth_noise(frame.depth, depth, 1000 + static_cast<uint64_t>(k));
      apply_detection_noise(frame, detection, 2000 + static_cast<uint64_t>(k));

      // The node's share before the pipeline: decoding CAMERA_DEPTH (raw) and CAMERA_LABELS
      // (run-length), the simulator's default codecs.
      if (k % 10 == 0) {
        const auto dm = depth_message(frame, semx::runtime::ImageCompression::kNone);
        const auto lm = label_message(frame, semx::runtime::ImageCompression::kRle);
        Frame f;
        const auto t0 = Clock::now();
        set_camera(dm.info, dm.utime, f);
        fill_depth(dm, f);
        fill_labels(lm, f);
        decode.push_back(ms_since(t0));
      }
      const Frame f = to_frame(frame);
      const double c0 = thread_cpu_ms();
      const FrameStats s = pipeline.process(f);
      cpu.push_back(thread_cpu_ms() - c0);
      total.push_back(s.total_ms());
      detect.push_back(s.detect_ms);
      lift.push_back(s.lift_ms);
      track.push_back(s.track_ms);
      detections += static_cast<std::size_t>(s.detections_2d);
    }
    std::printf("frames: %d frames (640x480, env2 survey path, detection + depth noise)\n", frames);
    std::printf("detections_per_frame: %.1f detections\n", static_cast<double>(detections) / frames);
    std::printf("tracks_at_end: %zu tracks\n", pipeline.tracker().tracks().size());
    std::printf("regions_at_end: %zu regions\n", pipeline.regions().size());
    std::printf("frame_ms_mean: %.2f ms\n", mean(total));
    std::printf("frame_ms_median: %.2f ms\n", percentile(total, 0.5));
    std::printf("frame_ms_p95: %.2f ms\n", percentile(total, 0.95));
    std::printf("frame_ms_max: %.2f ms\n", percentile(total, 1.0));
    std::printf("frame_cpu_ms_mean: %.2f ms\n", mean(cpu));
    std::printf("frame_cpu_ms_p95: %.2f ms\n", percentile(cpu, 0.95));
    std::printf("detect_ms_mean: %.2f ms\n", mean(detect));
    std::printf("lift_ms_mean: %.2f ms\n", mean(lift));
    std::printf("track_ms_mean: %.2f ms\n", mean(track));
    std::printf("node_decode_ms_mean: %.2f ms\n", mean(decode));
    return 0;
  });
}
