// The semantics library on the simulator, in one process (no LCM): the simulator's camera frames
// as semantics frames, a scripted camera path through a world, and the accuracy evaluation of
// semx-semantics-accuracy (regions against the world's ground-truth objects).
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "semx/semantics/config.hpp"
#include "semx/semantics/frame.hpp"
#include "semx/semantics/regions.hpp"
#include "semx/semantics/tracker.hpp"
#include "semx/simulator/camera_frame.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/sensor_noise.hpp"
#include "semx/simulator/world.hpp"

namespace semx::semantics {

// Copies a rendered frame (whatever channels it has) into a semantics Frame.
Frame to_frame(const simulator::CameraFrame& f);

// A camera path: the vehicle's body centre and yaw at each step (the camera is level and looks
// along the body's x axis, as in the simulator).
struct PathPose {
  Eigen::Vector3d position;
  double yaw;
};
// Waypoints flown at `speed` (turning in place to face each leg first, at `yaw_rate`); a waypoint
// with spin = true adds a full turn there. Poses every 1 / rate_hz seconds.
struct Waypoint {
  Eigen::Vector3d position;
  bool spin = false;
  bool jump = false;  // arrive at once (no frames along the leg; the camera does not fly through walls)
};
std::vector<PathPose> sample_path(const std::vector<Waypoint>& waypoints, double start_yaw, double speed,
                                  double yaw_rate, double rate_hz);
// The survey path through both rooms of env2 used for the accuracy figure (1.4 m high).
std::vector<Waypoint> env2_survey_path();
// For any world: a full turn at every point of a `spacing` grid (1.4 m high) that the vehicle can
// reach from the start, visited nearest first, jumping between them.
std::vector<Waypoint> survey_stops(const simulator::World& world, double spacing = 2.0);

struct AccuracyOptions {
  std::string world = "env2";
  std::vector<Waypoint> path;  // empty: env2_survey_path() on env2, else survey_stops()
  double speed = 0.5;          // m/s
  double yaw_rate = 0.6;       // rad/s
  double rate_hz = 30.0;       // camera frames per second
  double max_seconds = 0.0;    // stop early (0: the whole path)
  uint64_t seed = 1;
  simulator::DetectionNoiseConfig detection_noise;  // enabled by default below
  simulator::DepthNoiseConfig depth_noise;
  double match_distance = 0.5;  // a region matches an object of its class within this, m
  double min_view_s = 1.0;      // recall counts objects in view this long without a break
  AccuracyOptions() {
    detection_noise.enabled = true;
    depth_noise.enabled = true;
  }
};

struct ClassScore {
  int regions = 0;          // published regions of this class
  int true_regions = 0;     // ... matched to an object
  int objects_in_view = 0;  // objects in view >= min_view_s
  int found = 0;            // ... matched by a region
  double error_sum = 0.0;   // centroid errors of matched regions
  double error_max = 0.0;
  double precision() const { return regions ? static_cast<double>(true_regions) / regions : 1.0; }
  double recall() const { return objects_in_view ? static_cast<double>(found) / objects_in_view : 1.0; }
  double error_mean() const { return true_regions ? error_sum / true_regions : 0.0; }
};

struct RegionMatch {
  Region region;
  int object = -1;  // index into AccuracyReport::objects, -1 for a false positive
  double error = 0;
};

struct AccuracyReport {
  std::string world;
  int frames = 0;
  int frames_processed = 0;  // of which processed (detector.frame_period_s)
  double seconds = 0;        // message time covered
  double ms_per_frame = 0;   // semantics pipeline, wall time per processed frame
  std::vector<simulator::ObjectInfo> objects;
  std::vector<double> longest_view_s;  // per object
  std::vector<RegionMatch> matches;    // one per published region
  std::map<runtime::SemanticClass, ClassScore> classes;
  ClassScore total;
  int regions_inactive = 0;
  int64_t tracks = 0;
  std::vector<Track> final_tracks;  // every track at the end, regions or not (for diagnosis)
};

using ProgressFn = std::function<void(int frame, double seconds, std::size_t regions)>;

AccuracyReport run_accuracy(const AccuracyOptions& options, const SemanticsConfig& config,
                            const ProgressFn& progress = nullptr);

// Matches regions to objects of the same class, nearest pairs first, one-to-one, within
// match_distance; fills matches, classes and total (objects count when in view long enough).
void score_regions(const std::vector<Region>& regions, AccuracyReport& report, double match_distance,
                   double min_view_s);

}  // namespace semx::semantics
