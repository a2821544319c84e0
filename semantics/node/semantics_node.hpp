// The semantics process around SemanticPipeline: CAMERA_DEPTH + CAMERA_LABELS (and CAMERA_RGB
// when the detector needs it) paired by camera_info.frame_id, SEMANTIC_REGIONS out on change and
// at least every regions.publish_period_s of message time (checked after every frame and on
// every SIM_CLOCK tick, so in LOCKSTEP the regions of a tick are on the wire before its ack).
#pragma once

#include <semx/camera_info_t.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>

#include "semx/runtime/frame_gate.hpp"
#include "semx/runtime/node.hpp"
#include "semx/semantics/config.hpp"
#include "semx/semantics/pipeline.hpp"
#include "semx/semantics/regions.hpp"

namespace semx::semantics {

struct SemanticsNodeCounters {
  int64_t frames_processed = 0;
  int64_t frames_skipped = 0;     // not due (detector.frame_period_s): dropped unread
  int64_t frames_rejected = 0;    // complete, but the pipeline refused them (see last_reject)
  int64_t frames_incomplete = 0;  // parts dropped before the rest arrived
  int64_t parts_mismatched = 0;   // parts of one frame_id with different camera sizes
  int64_t bad_payload = 0;        // passed the checks but did not decompress
  int64_t regions_published = 0;
  double process_ms = 0.0;  // wall time in the pipeline, for the exit summary only
};

class SemanticsNode {
 public:
  SemanticsNode(runtime::NodeOptions options, const SemanticsConfig& config);

  runtime::Node& node() { return node_; }
  const runtime::Node& node() const { return node_; }
  const SemanticPipeline& pipeline() const { return pipeline_; }
  const SemanticsNodeCounters& counters() const { return counters_; }
  const std::string& last_reject() const { return last_reject_; }
  int run() { return node_.run(); }
  // Called after each SEMANTIC_REGIONS publication; `changed` is false for the periodic ones.
  void on_publish(std::function<void(const std::vector<Region>&, int64_t utime, bool changed)> fn) {
    on_publish_ = std::move(fn);
  }

  // Frames waiting for their other parts, at most this many (the oldest is dropped).
  static constexpr std::size_t kMaxPending = 4;

 private:
  struct Pending {
    Frame frame;
    bool depth = false, labels = false, rgb = false;
    int32_t width = 0, height = 0;
    uint64_t arrival = 0;
  };
  Pending* part(const semx::camera_info_t& info, int64_t utime);
  void complete(int64_t frame_id);
  void process(const Frame& frame);
  // Frames wait for their tick's ack (detector.latency_s > 0). Without a clock no tick would
  // ever process them (frames fed by hand): at once, as with latency 0.
  bool deferring() const { return latency_us_ > 0 && node_.clock().started(); }
  void on_tick(int64_t utime);
  void maybe_publish(int64_t utime);
  void update_state();

  SemanticsConfig config_;
  runtime::Node node_;
  SemanticPipeline pipeline_;
  RegionPublisher publisher_;
  runtime::FrameGate gate_;
  bool need_labels_, need_rgb_;
  std::map<int64_t, Pending> pending_;
  // detector.latency_s > 0: the complete frame waiting for its tick's ack, and the message time
  // from which what it changed may go out (-1: none).
  int64_t latency_us_ = 0;
  std::optional<Frame> deferred_;
  int64_t publish_at_ = -1;
  uint64_t arrivals_ = 0;
  SemanticsNodeCounters counters_;
  std::string last_reject_;
  int64_t seq_ = 0;
  std::size_t last_region_count_ = static_cast<std::size_t>(-1);
  std::size_t last_active_count_ = 0;
  std::function<void(const std::vector<Region>&, int64_t, bool)> on_publish_;
};

}  // namespace semx::semantics
