#include "semx/semantics/pipeline.hpp"

#include <chrono>

namespace semx::semantics {

namespace {
using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

SemanticPipeline::SemanticPipeline(const SemanticsConfig& config, std::unique_ptr<Detector> detector)
    : config_(config),
      detector_(detector ? std::move(detector) : make_detector(config)),
      lifter_(config.lift),
      tracker_(config) {}

void SemanticPipeline::reset() {
  tracker_.clear();
  last_utime_ = -1;
}

FrameStats SemanticPipeline::process(const Frame& frame) {
  FrameStats s;
  ++counters_.frames;
  s.reject_reason = validate(frame);
  if (s.reject_reason.empty() && detector_->needs_labels() && !frame.has_labels()) {
    s.reject_reason = "the " + detector_->name() + " detector needs a label image";
  }
  if (s.reject_reason.empty() && detector_->needs_rgb() && !frame.has_rgb()) {
    s.reject_reason = "the " + detector_->name() + " detector needs an RGB image";
  }
  if (!s.reject_reason.empty()) {
    ++counters_.rejected;
    return s;
  }
  if (last_utime_ >= 0 && frame.utime < last_utime_) {
    // Time went backwards: a new episode; nothing of the old one applies.
    tracker_.clear();
    ++counters_.episodes;
  }
  last_utime_ = frame.utime;
  s.accepted = true;

  const auto t0 = Clock::now();
  const std::vector<Detection2D> d2 = detector_->detect(frame);
  const auto t1 = Clock::now();
  std::vector<Detection3D> d3;
  d3.reserve(d2.size());
  for (const auto& d : d2) {
    LiftOutcome outcome;
    auto lifted = lifter_.lift(frame, d, &outcome);
    if (lifted) {
      d3.push_back(std::move(*lifted));
    } else if (outcome == LiftOutcome::kNoDepth) {
      ++s.lift_no_depth;
    } else {
      ++s.lift_too_few_points;
    }
  }
  const auto t2 = Clock::now();
  s.tracker = tracker_.update(frame, d3);
  const auto t3 = Clock::now();

  s.detections_2d = static_cast<int>(d2.size());
  s.detections_3d = static_cast<int>(d3.size());
  counters_.detections_2d += s.detections_2d;
  counters_.detections_3d += s.detections_3d;
  s.detect_ms = ms_between(t0, t1);
  s.lift_ms = ms_between(t1, t2);
  s.track_ms = ms_between(t2, t3);
  return s;
}

}  // namespace semx::semantics
