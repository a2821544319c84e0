// The one typed configuration of the semantics module (docs/semantics.md, "Parameters"), read
// strictly from YAML by `load(ConfigMap&, SemanticsConfig&)`; defaults are the values below.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/runtime/config.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::semantics {

inline constexpr std::size_t kClassCount = static_cast<std::size_t>(runtime::SemanticClass::kCount);

// The learned detector: a semantic-segmentation network in ONNX, run by OpenCV DNN on the RGB
// image; its per-pixel arg-max becomes a label image that goes through the same mask pipeline.
struct DnnConfig {
  std::string model;  // path to the .onnx file (required when detector.type is dnn)
  int input_width = 320;
  int input_height = 240;
  double scale = 1.0 / 255.0;         // blob = (pixel - mean) * scale
  std::vector<double> mean{0, 0, 0};  // R, G, B
  bool swap_rb = false;               // feed BGR instead of RGB
  std::vector<std::string> classes;   // semx class name of each output channel ("none" = skip)
  double min_score = 0.5;             // pixels whose best softmax score is lower are background
};

struct DetectorConfig {
  std::string type = "labels";  // labels | dnn
  // Split masks by the label image's instance ids (an instance-segmenting camera). Off: one
  // detection per connected component of a class mask (a semantic-only segmentation).
  bool use_instances = true;
  int min_area_px = 80;     // smaller components are dropped
  int morph_kernel_px = 3;  // square opening kernel (1 = no clean-up)
  // At most one frame per this much message time is processed (0 = every frame); see FrameGate.
  double frame_period_s = 0.1;
  // s of message time from a frame to the regions it changes: a detector's latency, as the
  // mapper's streaming.lockstep_delay. The frame is processed after its tick's ack, so in LOCKSTEP
  // the clock goes on meanwhile (0 = processed and published before the ack).
  double latency_s = 0.05;
  DnnConfig dnn;
};

struct LiftConfig {
  // Pixels are back-projected on a grid whose spacing on the object is about
  // voxel_size / 2 (stride = voxel_size * fx / (2 z)), clamped to [1, max_pixel_stride].
  int max_pixel_stride = 16;
  double voxel_size = 0.08;         // PCL VoxelGrid leaf, m (also the tracks' surface voxels)
  int outlier_neighbours = 8;       // StatisticalOutlierRemoval mean_k (0 = off)
  double outlier_stddev = 2.0;      // ... stddev multiplier
  double cluster_tolerance = 0.12;  // EuclideanClusterExtraction, m
  int min_points = 6;               // fewer voxels after filtering: no 3D detection
};

struct TrackingConfig {
  double gate_distance = 0.25;        // max gap between a detection's box and a track's box, m
  int min_observations = 5;           // K: detections before a track becomes a region
  double min_duration_s = 0.5;        // T: message time between the first and the K-th detection
  double promote_probability = 0.7;   // existence probability needed to become a region
  double log_odds_hit = 0.85;         // existence log-odds added per detection
  double log_odds_miss = 0.4;         // ... removed per frame in view without a detection
  double region_log_odds_miss = 0.1;  // ... for a region: a confirmed object needs more to go
  double log_odds_max = 4.0;
  double drop_log_odds = -2.0;       // below: the track (or region) is deleted
  double tentative_timeout_s = 3.0;  // a track that is not a region and unseen this long is deleted
  int voxel_min_observations = 2;    // surface voxels seen in fewer frames do not shape the box,
  double voxel_min_fraction = 0.02;  // ... nor those seen in less than this fraction of the frames
                                     // that saw the track's best-seen voxel
  double merge_overlap = 0.5;        // same-class tracks whose boxes overlap by this much merge
  // A track overlapping (merge_overlap) a track of another class with this many times its
  // observations is a label confusion: never promoted, demoted if it was (0 = off).
  double confusion_ratio = 3.0;
  // Observed fraction (docs/semantics.md, "Observed fraction and the fully-observed rule").
  double face_cell = 0.1;   // m
  double free_probe = 0.5;  // m in front of a face cell that must be seen free
  double fully_observed_fraction = 0.8;
  double min_known_fraction = 0.4;
};

struct ClassParams {
  bool enabled = false;  // detected and turned into regions
  double weight = 0.0;   // w (times regions.weight_scale)
  double radius = 0.0;   // base influence radius, m
};

struct RegionConfig {
  double weight_scale = 100.0;      // converts class weights to the planner's gain units
  double radius_extent_gain = 1.0;  // r = radius + gain * half the box diagonal
  double publish_period_s = 1.0;    // SEMANTIC_REGIONS at least this often (message time)
  double change_distance = 0.05;    // centroid or radius moves beyond this count as a change, m
  double change_fraction = 0.05;    // observed_fraction moves beyond this count as a change
  std::array<ClassParams, kClassCount> classes = default_classes();

  static std::array<ClassParams, kClassCount> default_classes();
  const ClassParams& of(runtime::SemanticClass c) const { return classes[static_cast<std::size_t>(c)]; }
};

struct SemanticsConfig {
  DetectorConfig detector;
  LiftConfig lift;
  TrackingConfig tracking;
  RegionConfig regions;
};

void load(runtime::ConfigMap& m, SemanticsConfig& c);

}  // namespace semx::semantics
