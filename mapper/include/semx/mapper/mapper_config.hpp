// Every parameter of the mapper, with its default, in one place (docs/mapper.md quotes this).
//
// YAML layout (all keys optional; unknown keys are errors):
//   resolution: 0.1
//   occupancy:   { prob_hit, prob_miss, clamp_min, clamp_max, threshold, hold_range, bounds_min,
//                  bounds_max }
//   integration: { min_range, max_range, pixel_step, frame_period_s, mode }
//   esdf:        { enabled, window, max_distance, unknown_as_occupied }
//   streaming:   { snapshot_period, stats_period, esdf_period, lockstep_delay }
//   checkpoint:  { path, period }
#pragma once

#include <string>
#include <vector>

#include "semx/runtime/config.hpp"

namespace semx::mapper {

struct OccupancyParams {
  double resolution = 0.1;  // m, voxel edge
  // OctoMap's defaults (OccupancyOcTreeBase), so maps built here and by OctoMap agree.
  double prob_hit = 0.7;      // sensor model: P(occupied | ray ends in the voxel)
  double prob_miss = 0.4;     // sensor model: P(occupied | ray passes through the voxel)
  double clamp_min = 0.1192;  // log-odds are clamped to [logit(clamp_min), logit(clamp_max)]
  double clamp_max = 0.971;   // so a voxel can change its mind after a few observations
  double threshold = 0.5;     // occupied iff P >= threshold (log-odds >= logit(threshold))
  // m; 0 = OctoMap's rule everywhere. A voxel that reaches clamp_max on a hit from at most this
  // range is held occupied: later misses no longer lower it. Why: a voxel only partly filled (the
  // end of a 4 cm door leaf) is hit from one side and passed through from another, and OctoMap's
  // clamp lets ten grazing frames clear what forty close ones saw; the body then flew into it
  // (docs/mapper.md, "Thin obstacles"). Only close hits hold: far ones carry depth noise of a
  // voxel or more, and a doorway's edge seen from afar must still clear when seen up close. It
  // assumes a static world, as the worlds here are.
  double hold_range = 2.0;
  // Optional world limits of the map, metres: voxels whose centre is outside are never updated
  // (rays still pass through). Both empty (default): the map grows to cover whatever is seen.
  std::vector<double> bounds_min;
  std::vector<double> bounds_max;
};

struct IntegrationParams {
  // Valid z-depth interval, metres along the optical axis, intersected with the camera's own
  // [min_range, max_range] from each frame. Shorter depths are ignored; longer ones (and
  // 0xFFFF "no return") clear free space up to max_range without marking an obstacle.
  double min_range = 0.0;
  double max_range = 5.0;
  // Integrate every pixel_step-th pixel in both directions (1 = the full frame).
  int pixel_step = 1;
  // s of message time: at most one depth frame per this much is integrated (0 = every frame).
  // The camera's 30 frames a second overlap almost entirely (3 cm apart at 1 m/s); 10 a second
  // (a voxel apart) map the same space for a third of the work (docs/mapper.md, "Frame rate").
  double frame_period_s = 0.1;
  // How rays are walked (depth_integrator.hpp; speed and agreement in docs/mapper.md):
  //   exact:   every pixel's ray, end to camera: OctoMap's insertPointCloud, voxel for voxel;
  //   bundled: one ray per end voxel and quadrant of it (default; 99.6-99.8 % agreement);
  //   fast:    one ray per end voxel, stopping at the first voxel an earlier ray walked
  //            (Fast-Planner's scheme: fastest, but leaves holes in free space).
  enum class Mode { kExact, kBundled, kFast };
  Mode mode = Mode::kBundled;
};

struct EsdfParams {
  bool enabled = true;
  std::vector<double> window = {10.0, 10.0, 3.0};  // m, x y z extent, centred on the vehicle
  double max_distance = 3.0;                       // m, distances are clamped to +-max_distance
  bool unknown_as_occupied = true;                 // unknown space is an obstacle (safe default)
};

// Publishing cadence of the mapper node (simulation time, seconds; 0 disables).
struct StreamingParams {
  double snapshot_period = 5.0;  // MAP_SNAPSHOT, besides those sent on request
  double stats_period = 1.0;     // MAP_STATS (counts frontiers over the whole map)
  // ESDF_LOCAL; 0 = after every integrated frame. 0.2 s (5 Hz) because each message is the whole
  // window (1.2 MB at the defaults) and each recompute ~8 ms: every frame (30 Hz) made the ESDF
  // the largest cost of a lockstep run, while the controller needs it far less often (it brakes
  // on a 2 s horizon and calls an ESDF stale after safety.max_esdf_age = 1 s).
  double esdf_period = 0.2;
  // LOCKSTEP only: a frame is integrated (and its ESDF computed) on a worker thread while the
  // simulator and the other nodes go on, and its MAP_UPDATE / ESDF_LOCAL are published by the
  // first tick at least this long after the frame (message time, so every run publishes them at
  // the same tick). 0 = in the frame's handler, before the ack of the frame's own tick. 0.09 s:
  // the integration overlaps the other nodes' next 9 ticks, within the clock's 0.1 s max_slack
  // (env3's first 120 s: 25.4 s of wall time against 27.5 s with 0.04 s; docs/runtime.md).
  double lockstep_delay = 0.09;
};

struct CheckpointParams {
  std::string path;      // empty: no checkpoints. Loaded on start when the file exists.
  double period = 30.0;  // s of simulation time between checkpoints
};

struct MapperConfig {
  OccupancyParams occupancy;
  IntegrationParams integration;
  EsdfParams esdf;
  StreamingParams streaming;
  CheckpointParams checkpoint;
};

// Reads the keys above from `m` (strict: wrong types and out-of-range values name the key) and
// checks cross-field constraints.
void load(runtime::ConfigMap& m, MapperConfig& c);
const char* to_string(IntegrationParams::Mode m);
// The cross-field checks alone, for configs built in code; throws runtime::ConfigError.
void validate(const MapperConfig& c);
void validate(const OccupancyParams& p);

}  // namespace semx::mapper
