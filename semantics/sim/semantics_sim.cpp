#include "semantics_sim.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "semx/runtime/frame_gate.hpp"
#include "semx/semantics/pipeline.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/rasterizer.hpp"

namespace semx::semantics {

Frame to_frame(const simulator::CameraFrame& f) {
  Frame out;
  out.utime = f.utime;
  out.frame_id = f.frame_id;
  out.camera = f.camera;
  out.pose = f.pose;
  if (f.channels & simulator::kRenderDepth) out.depth = f.depth.data;
  if (f.channels & simulator::kRenderLabels) {
    out.class_label = f.class_label.data;
    out.instance_label = f.instance_label.data;
  }
  if (f.channels & simulator::kRenderRgb) {
    out.rgb.resize(3 * f.rgb.data.size());
    for (std::size_t i = 0; i < f.rgb.data.size(); ++i) {
      out.rgb[3 * i] = f.rgb.data[i].r;
      out.rgb[3 * i + 1] = f.rgb.data[i].g;
      out.rgb[3 * i + 2] = f.rgb.data[i].b;
    }
  }
  return out;
}

namespace {
double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }
}  // namespace

std::vector<PathPose> sample_path(const std::vector<Waypoint>& waypoints, double start_yaw, double speed,
                                  double yaw_rate, double rate_hz) {
  std::vector<PathPose> out;
  if (waypoints.empty() || !(speed > 0) || !(yaw_rate > 0) || !(rate_hz > 0)) return out;
  const double dt = 1.0 / rate_hz;
  Eigen::Vector3d p = waypoints.front().position;
  double yaw = start_yaw;
  out.push_back({p, yaw});
  auto turn_by = [&](double angle) {
    const int n = static_cast<int>(std::ceil(std::abs(angle) / (yaw_rate * dt)));
    const double start = yaw;
    for (int k = 1; k <= n; ++k) out.push_back({p, wrap(start + angle * k / n)});
    yaw = wrap(start + angle);
  };
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (i > 0 && waypoints[i].jump) {
      p = waypoints[i].position;
      out.push_back({p, yaw});
    } else if (i > 0) {
      const Eigen::Vector3d a = p, b = waypoints[i].position;
      const Eigen::Vector3d d = b - a;
      if (d.head<2>().norm() > 1e-6) turn_by(wrap(std::atan2(d.y(), d.x()) - yaw));
      const int n = static_cast<int>(std::ceil(d.norm() / (speed * dt)));
      for (int k = 1; k <= n; ++k) {
        p = a + d * (static_cast<double>(k) / n);
        out.push_back({p, yaw});
      }
      p = b;
    }
    if (waypoints[i].spin) turn_by(2 * M_PI);
  }
  return out;
}

std::vector<Waypoint> env2_survey_path() {
  const double h = 1.4;
  return {
      {{3.0, 2.0, h}, true},   {{3.0, 4.4, h}, false},  {{6.0, 4.0, h}, true},  {{7.2, 3.0, h}, false},
      {{6.0, 0.9, h}, false},  {{2.5, 1.2, h}, true},   {{7.3, 3.0, h}, false}, {{10.9, 3.0, h}, true},
      {{12.5, 1.7, h}, false}, {{14.5, 3.0, h}, true},  {{16.3, 3.3, h}, true}, {{14.2, 4.6, h}, false},
      {{12.0, 4.7, h}, true},  {{10.9, 2.0, h}, false},
  };
}

std::vector<Waypoint> survey_stops(const simulator::World& world, double spacing) {
  const simulator::GroundTruth gt(world, 0.1);
  const simulator::VehicleReachability reach(gt, world.start.position);
  std::vector<Eigen::Vector3d> todo;
  const auto& b = world.bounds;
  for (double x = b.min.x() + spacing / 2; x < b.max.x(); x += spacing) {
    for (double y = b.min.y() + spacing / 2; y < b.max.y(); y += spacing) {
      const Eigen::Vector3d p(x, y, 1.4);
      if (reach.reachable(p)) todo.push_back(p);
    }
  }
  std::vector<Waypoint> out;
  Eigen::Vector3d at(world.start.position.x(), world.start.position.y(), 1.4);
  out.push_back({at, true, false});
  while (!todo.empty()) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < todo.size(); ++i) {
      if ((todo[i] - at).norm() < (todo[best] - at).norm()) best = i;
    }
    at = todo[best];
    todo.erase(todo.begin() + static_cast<std::ptrdiff_t>(best));
    out.push_back({at, true, true});
  }
  return out;
}

void score_regions(const std::vector<Region>& regions, AccuracyReport& report, double match_distance,
                   double min_view_s) {
  report.matches.clear();
  report.classes.clear();
  report.total = ClassScore{};
  report.regions_inactive = 0;
  struct Pair {
    double d;
    std::size_t r, o;
  };
  std::vector<Pair> pairs;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    for (std::size_t o = 0; o < report.objects.size(); ++o) {
      if (regions[r].cls != report.objects[o].cls) continue;
      const double d = (regions[r].centroid - report.objects[o].center).norm();
      if (d <= match_distance) pairs.push_back({d, r, o});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<int> region_object(regions.size(), -1);
  std::vector<double> region_error(regions.size(), 0.0);
  std::vector<char> object_taken(report.objects.size(), 0);
  for (const Pair& p : pairs) {
    if (region_object[p.r] >= 0 || object_taken[p.o]) continue;
    region_object[p.r] = static_cast<int>(p.o);
    region_error[p.r] = p.d;
    object_taken[p.o] = 1;
  }
  auto add = [&](runtime::SemanticClass c, auto&& fn) {
    fn(report.classes[c]);
    fn(report.total);
  };
  for (std::size_t r = 0; r < regions.size(); ++r) {
    report.matches.push_back({regions[r], region_object[r], region_error[r]});
    if (!regions[r].active) ++report.regions_inactive;
    add(regions[r].cls, [&](ClassScore& s) {
      ++s.regions;
      if (region_object[r] >= 0) {
        ++s.true_regions;
        s.error_sum += region_error[r];
        s.error_max = std::max(s.error_max, region_error[r]);
      }
    });
  }
  for (std::size_t o = 0; o < report.objects.size(); ++o) {
    if (report.longest_view_s[o] < min_view_s) continue;
    add(report.objects[o].cls, [&](ClassScore& s) {
      ++s.objects_in_view;
      if (object_taken[o]) ++s.found;
    });
  }
}

AccuracyReport run_accuracy(const AccuracyOptions& opt, const SemanticsConfig& config,
                            const ProgressFn& progress) {
  using namespace simulator;
  const World world = load_world(shipped_world_path(opt.world));
  AccuracyReport report;
  report.world = world.name.empty() ? opt.world : world.name;
  report.objects = list_objects(world);
  report.longest_view_s.assign(report.objects.size(), 0.0);
  std::map<uint16_t, std::size_t> object_of_instance;
  for (std::size_t o = 0; o < report.objects.size(); ++o) object_of_instance[report.objects[o].instance] = o;

  const bool env2 = world.name == "env2";
  const std::vector<Waypoint> waypoints =
      !opt.path.empty() ? opt.path : (env2 ? env2_survey_path() : survey_stops(world));
  const std::vector<PathPose> poses =
      sample_path(waypoints, world.start.yaw, opt.speed, opt.yaw_rate, opt.rate_hz);

  Rasterizer raster(world);
  const runtime::PinholeCamera camera;
  SemanticPipeline pipeline(config);
  // The node's frame rate (detector.frame_period_s), so the figures are those of semx-semantics.
  runtime::FrameGate gate(config.detector.frame_period_s);
  CameraFrame frame;
  std::vector<double> run_start(report.objects.size(), -1.0);
  std::vector<int> pixels(report.objects.size());
  double pipeline_ms = 0;
  const double dt = 1.0 / opt.rate_hz;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const double t = static_cast<double>(k) * dt;
    if (opt.max_seconds > 0 && t > opt.max_seconds) break;
    VehicleState state;
    state.position = poses[k].position;
    state.yaw = poses[k].yaw;
    raster.render(camera, state.camera_pose(), kRenderDepth | kRenderLabels, frame);
    frame.utime = static_cast<int64_t>(std::llround(t * 1e6));
    frame.frame_id = static_cast<int64_t>(k);

    // Ground truth from the clean labels: objects with enough measured pixels are in view.
    std::fill(pixels.begin(), pixels.end(), 0);
    for (std::size_t i = 0; i < frame.instance_label.data.size(); ++i) {
      const uint16_t d = frame.depth.data[i];
      if (d == runtime::kDepthInvalid || d == runtime::kDepthNoReturn) continue;
      const auto it = object_of_instance.find(frame.instance_label.data[i]);
      if (it != object_of_instance.end() &&
          report.objects[it->second].cls == static_cast<runtime::SemanticClass>(frame.class_label.data[i])) {
        ++pixels[it->second];
      }
    }
    for (std::size_t o = 0; o < pixels.size(); ++o) {
      if (pixels[o] >= config.detector.min_area_px) {
        if (run_start[o] < 0) run_start[o] = t;
        report.longest_view_s[o] = std::max(report.longest_view_s[o], t - run_start[o] + dt);
      } else {
        run_start[o] = -1;
      }
    }

    const uint64_t seed = opt.seed * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(k);
    apply_depth_noise(frame.depth, opt.depth_noise, seed ^ 0xD1B54A32D192ED03ull);
    apply_detection_noise(frame, opt.detection_noise, seed);

    if (gate.due(frame.utime)) {
      gate.taken(frame.utime);
      const Frame f = to_frame(frame);
      const auto t0 = std::chrono::steady_clock::now();
      pipeline.process(f);
      pipeline_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ++report.frames_processed;
    }
    ++report.frames;
    report.seconds = t;
    if (progress && k % 300 == 0) progress(static_cast<int>(k), t, pipeline.regions().size());
  }
  report.ms_per_frame = report.frames_processed ? pipeline_ms / report.frames_processed : 0.0;
  report.tracks = static_cast<int64_t>(pipeline.tracker().tracks().size());
  report.final_tracks = pipeline.tracker().tracks();
  score_regions(pipeline.regions(), report, opt.match_distance, opt.min_view_s);
  return report;
}

}  // namespace semx::semantics
