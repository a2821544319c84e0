// The semantics module's logic as one object: frame in, regions out.
//
//   SemanticPipeline sem(config);            // detector from config.detector.type
//   FrameStats s = sem.process(frame);       // detect, lift, track
//   std::vector<Region> r = sem.regions();   // S_i = (p, l, w, r) of the promoted tracks
//
// Everything runs on the frames' message time; a frame older than the previous one starts a new
// episode (the tracks are cleared). Wall-clock timings are measured for statistics only.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "semx/semantics/config.hpp"
#include "semx/semantics/detector.hpp"
#include "semx/semantics/frame.hpp"
#include "semx/semantics/lifter.hpp"
#include "semx/semantics/regions.hpp"
#include "semx/semantics/tracker.hpp"

namespace semx::semantics {

struct FrameStats {
  bool accepted = false;
  std::string reject_reason;  // when not accepted
  int detections_2d = 0;
  int detections_3d = 0;
  int lift_no_depth = 0;
  int lift_too_few_points = 0;
  TrackerStats tracker;
  double detect_ms = 0, lift_ms = 0, track_ms = 0;  // wall time (statistics only)
  double total_ms() const { return detect_ms + lift_ms + track_ms; }
};

struct PipelineCounters {
  int64_t frames = 0;
  int64_t rejected = 0;
  int64_t episodes = 0;  // resets because time went backwards
  int64_t detections_2d = 0;
  int64_t detections_3d = 0;
};

class SemanticPipeline {
 public:
  // `detector` null: make_detector(config).
  explicit SemanticPipeline(const SemanticsConfig& config, std::unique_ptr<Detector> detector = nullptr);

  FrameStats process(const Frame& frame);
  std::vector<Region> regions() const { return make_regions(tracker_.tracks(), config_.regions); }
  void reset();

  const SemanticsConfig& config() const { return config_; }
  const Detector& detector() const { return *detector_; }
  const ObjectTracker& tracker() const { return tracker_; }
  const PipelineCounters& counters() const { return counters_; }
  int64_t last_utime() const { return last_utime_; }

 private:
  SemanticsConfig config_;
  std::unique_ptr<Detector> detector_;
  ObjectLifter lifter_;
  ObjectTracker tracker_;
  PipelineCounters counters_;
  int64_t last_utime_ = -1;
};

}  // namespace semx::semantics
