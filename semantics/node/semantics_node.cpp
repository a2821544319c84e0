#include "semantics_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "semantics_messages.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::semantics {

SemanticsNode::SemanticsNode(runtime::NodeOptions options, const SemanticsConfig& config)
    : config_(config),
      node_(std::move(options)),
      pipeline_(config),
      publisher_(config.regions),
      gate_(config.detector.frame_period_s) {
  latency_us_ = static_cast<int64_t>(std::llround(config.detector.latency_s * 1e6));
  need_labels_ = pipeline_.detector().needs_labels();
  need_rgb_ = pipeline_.detector().needs_rgb();
  // Captures that are not due are dropped from their bytes' utime, before the 0.3-1 MB images
  // are validated, copied and decompressed. The gate changes only when a frame is processed, so
  // every part of one capture (same utime) gets the same answer.
  node_.skip_unless(semx::channels::CAMERA_DEPTH, [this](int64_t utime) {
    if (gate_.due(utime)) return true;
    ++counters_.frames_skipped;  // counted once per capture, on its depth part
    return false;
  });
  node_.skip_unless(semx::channels::CAMERA_LABELS, [this](int64_t utime) { return gate_.due(utime); });
  node_.skip_unless(semx::channels::CAMERA_RGB, [this](int64_t utime) { return gate_.due(utime); });
  node_.subscribe<semx::depth_image_t>(
      semx::channels::CAMERA_DEPTH,
      [this](const semx::depth_image_t& m) {
        Pending* p = part(m.info, m.utime);
        if (!p) return;
        if (!fill_depth(m, p->frame)) {
          ++counters_.bad_payload;
          pending_.erase(m.info.frame_id);
          return;
        }
        set_camera(m.info, m.utime, p->frame);  // the depth image's pose and time are the frame's
        p->depth = true;
        complete(m.info.frame_id);
      },
      accept_depth);
  if (need_labels_) {
    node_.subscribe<semx::label_image_t>(
        semx::channels::CAMERA_LABELS,
        [this](const semx::label_image_t& m) {
          Pending* p = part(m.info, m.utime);
          if (!p) return;
          if (!fill_labels(m, p->frame)) {
            ++counters_.bad_payload;
            pending_.erase(m.info.frame_id);
            return;
          }
          p->labels = true;
          complete(m.info.frame_id);
        },
        accept_labels);
  }
  if (need_rgb_) {
    node_.subscribe<semx::rgb_image_t>(
        semx::channels::CAMERA_RGB,
        [this](const semx::rgb_image_t& m) {
          Pending* p = part(m.info, m.utime);
          if (!p) return;
          if (!fill_rgb(m, p->frame)) {
            ++counters_.bad_payload;
            pending_.erase(m.info.frame_id);
            return;
          }
          p->rgb = true;
          complete(m.info.frame_id);
        },
        accept_rgb);
  }
  node_.on_tick([this](int64_t, int64_t utime) { on_tick(utime); });
  // Regions change only when a frame is processed, so nothing is published before the next frame
  // the gate takes (plus the latency) or the periodic repeat; a processed frame's regions wait
  // for publish_at_, and so does the repeat.
  node_.on_quiet_until([this](int64_t utime) {
    if (deferred_) return deferred_->utime + latency_us_;
    if (publish_at_ >= 0) return publish_at_;
    const int64_t frame = gate_.next_due();
    const int64_t repeat = publisher_.next_repeat_utime();
    if (frame == std::numeric_limits<int64_t>::min() || counters_.frames_processed == 0) return utime;
    return repeat < 0 ? frame + latency_us_ : std::min(frame + latency_us_, repeat);
  });
  node_.set_state(runtime::NodeState::kRunning, "waiting for camera frames");
}

SemanticsNode::Pending* SemanticsNode::part(const semx::camera_info_t& info, int64_t utime) {
  auto it = pending_.find(info.frame_id);
  if (it == pending_.end()) {
    if (pending_.size() >= kMaxPending) {
      // Drop the part that arrived first: its other parts are not coming.
      auto oldest = pending_.begin();
      for (auto i = pending_.begin(); i != pending_.end(); ++i) {
        if (i->second.arrival < oldest->second.arrival) oldest = i;
      }
      pending_.erase(oldest);
      ++counters_.frames_incomplete;
    }
    it = pending_.emplace(info.frame_id, Pending{}).first;
    it->second.width = info.width;
    it->second.height = info.height;
    it->second.arrival = arrivals_++;
    it->second.frame.utime = utime;
  } else if (it->second.width != info.width || it->second.height != info.height) {
    ++counters_.parts_mismatched;
    pending_.erase(it);
    return nullptr;
  }
  return &it->second;
}

void SemanticsNode::complete(int64_t frame_id) {
  auto it = pending_.find(frame_id);
  if (it == pending_.end()) return;
  const Pending& p = it->second;
  if (!p.depth || (need_labels_ && !p.labels) || (need_rgb_ && !p.rgb)) return;
  Frame frame = std::move(it->second.frame);
  pending_.erase(it);
  if (deferring()) {
    if (deferred_) process(*deferred_);  // two frames before one tick: the first one now
    deferred_ = std::move(frame);
    return;
  }
  process(frame);
}

void SemanticsNode::on_tick(int64_t utime) {
  if (publish_at_ >= 0 && utime >= publish_at_) publish_at_ = -1;
  if (publish_at_ < 0) maybe_publish(utime);
  if (!deferred_) return;
  node_.after_ack([this] {
    if (!deferred_) return;
    const Frame frame = std::move(*deferred_);
    deferred_.reset();
    process(frame);
  });
}

void SemanticsNode::process(const Frame& frame) {
  const FrameStats s = pipeline_.process(frame);
  counters_.process_ms += s.total_ms();
  if (!s.accepted) {
    ++counters_.frames_rejected;
    last_reject_ = s.reject_reason;
    return;
  }
  ++counters_.frames_processed;
  gate_.taken(frame.utime);
  if (deferring()) {
    // Frames closer than the latency (detector.frame_period_s = 0) go out with the first one's.
    if (publish_at_ < 0) publish_at_ = frame.utime + latency_us_;
  } else {
    maybe_publish(frame.utime);
  }
}

void SemanticsNode::maybe_publish(int64_t utime) {
  if (counters_.frames_processed == 0) return;  // nothing seen yet: no claims
  const std::vector<Region> regions = pipeline_.regions();
  const bool changed = publisher_.changed(regions);
  if (!publisher_.due(regions, utime)) return;
  node_.publish(semx::channels::SEMANTIC_REGIONS, to_message(regions, utime, seq_++));
  ++counters_.regions_published;
  if (on_publish_) on_publish_(regions, utime, changed);
  std::size_t active = 0;
  for (const auto& r : regions) active += r.active ? 1 : 0;
  if (regions.size() != last_region_count_ || active != last_active_count_) {
    last_region_count_ = regions.size();
    last_active_count_ = active;
    update_state();
  }
}

void SemanticsNode::update_state() {
  node_.set_state(runtime::NodeState::kRunning,
                  std::to_string(last_region_count_) + " regions (" + std::to_string(last_active_count_) +
                      " active), " + std::to_string(pipeline_.tracker().tracks().size()) + " tracks");
}

}  // namespace semx::semantics
