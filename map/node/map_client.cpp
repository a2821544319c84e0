#include "map_client.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include "map_messages.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::map {

namespace ch = semx::channels;

namespace {
bool same_resolution(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(a, b); }
}  // namespace

MapClient::MapClient(runtime::Node& node, MapClientOptions options)
    : node_(node), options_(std::move(options)) {
  apply_ = options_.apply;
  if (apply_ == MapClientOptions::Apply::kAuto) {
    apply_ = node_.clock().participant() ? MapClientOptions::Apply::kOnTick
                                         : MapClientOptions::Apply::kImmediately;
  }
  requester_ = options_.requester.empty() ? node_.name() : options_.requester;
  if (options_.resolution > 0)
    mirror_ = std::make_unique<MapMirror>(options_.resolution, options_.max_buffered);
  node_.subscribe<semx::map_update_t>(
      ch::MAP_UPDATE, [this](const semx::map_update_t& m) { on_update(m); }, &accept_update);
  node_.subscribe<semx::map_snapshot_t>(
      ch::MAP_SNAPSHOT, [this](const semx::map_snapshot_t& m) { on_snapshot(m); }, &accept_snapshot);
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  send_request(now());
}

const MapMirror& MapClient::mirror() const {
  if (!mirror_)
    throw std::logic_error("MapClient: no map yet (the resolution comes with the mapper's first message)");
  return *mirror_;
}

int64_t MapClient::now() const { return std::max(node_.now_utime(), latest_utime_); }

void MapClient::on_update(const semx::map_update_t& m) {
  ++counters_.updates;
  Held h;
  h.utime = m.utime;
  from_message(m, h.delta);  // accept_update already checked it
  latest_utime_ = std::max(latest_utime_, m.utime);
  if (apply_ == MapClientOptions::Apply::kOnTick) {
    hold(std::move(h));
  } else {
    apply(h);
    maybe_request(now());
  }
}

void MapClient::on_snapshot(const semx::map_snapshot_t& m) {
  ++counters_.snapshots;
  Held h;
  h.snapshot = true;
  h.utime = m.utime;
  h.snap = from_message(m);
  latest_utime_ = std::max(latest_utime_, m.utime);
  if (apply_ == MapClientOptions::Apply::kOnTick) {
    hold(std::move(h));
  } else {
    apply(h);
    maybe_request(now());
  }
}

void MapClient::hold(Held h) {
  held_.push_back(std::move(h));
  // Without ticks nothing would ever be applied: beyond a bound, apply the oldest now.
  while (held_.size() > 4 * options_.max_buffered + 16) {
    apply(held_.front());
    held_.pop_front();
  }
}

void MapClient::on_tick(int64_t /*tick*/, int64_t utime) {
  if (apply_ == MapClientOptions::Apply::kOnTick) {
    const bool restarted = last_tick_utime_ >= 0 && utime < last_tick_utime_;
    std::deque<Held> later;
    std::vector<Held> now;
    for (Held& h : held_) {
      if (restarted || h.utime < utime) {
        now.push_back(std::move(h));
      } else {
        later.push_back(std::move(h));
      }
    }
    held_.swap(later);
    // In the map's own order, not the order they came in: a snapshot sent again after a loss
    // (runtime delivery.hpp orders each channel, not snapshots against updates) would otherwise
    // follow the update after it, and the mirror would see a gap a lossless run does not.
    std::stable_sort(now.begin(), now.end(), [](const Held& a, const Held& b) {
      const int64_t sa = a.snapshot ? a.snap.seq : a.delta.seq, sb = b.snapshot ? b.snap.seq : b.delta.seq;
      // Delta s before the snapshot of map s, as the mapper sends them.
      return sa < sb || (sa == sb && !a.snapshot && b.snapshot);
    });
    for (const Held& h : now) apply(h);
  }
  last_tick_utime_ = utime;
  maybe_request(apply_ == MapClientOptions::Apply::kOnTick ? utime : now());
}

void MapClient::apply(const Held& h) {
  if (h.snapshot) {
    apply_snapshot(h.snap);
  } else {
    apply_delta(h.delta);
  }
}

void MapClient::apply_delta(const MapDelta& d) {
  if (!mirror_) mirror_ = std::make_unique<MapMirror>(d.resolution, options_.max_buffered);
  if (!same_resolution(d.resolution, mirror_->resolution())) {
    if (!options_.quiet && counters_.resolution_mismatches == 0) {
      std::cerr << node_.name() << ": MAP_UPDATE has " << d.resolution << " m voxels, the map client expects "
                << mirror_->resolution() << " m; ignoring such updates\n";
    }
    ++counters_.resolution_mismatches;
    return;
  }
  if (mirror_->apply(d) == MapMirror::DeltaResult::kApplied) {
    heard_ = true;
    if (on_delta_) on_delta_(mirror_->last_applied());
  }
}

void MapClient::apply_snapshot(const MapSnapshot& s) {
  outstanding_ = false;
  const bool adopt = !(options_.resolution > 0);
  if (mirror_ && !same_resolution(s.resolution, mirror_->resolution())) {
    ++counters_.resolution_mismatches;
    if (!adopt) {
      if (!options_.quiet && counters_.resolution_mismatches == 1) {
        std::cerr << node_.name() << ": MAP_SNAPSHOT has " << s.resolution
                  << " m voxels, the map client expects " << mirror_->resolution() << " m; ignoring it\n";
      }
      return;
    }
    // The mapper now maps at another resolution: start a new mirror if the snapshot is good.
    auto fresh = std::make_unique<MapMirror>(s.resolution, options_.max_buffered);
    if (fresh->apply(s) != MapMirror::SnapshotResult::kApplied) return;
    mirror_ = std::move(fresh);
    heard_ = true;
    if (on_reset_) on_reset_();
    return;
  }
  if (!mirror_) mirror_ = std::make_unique<MapMirror>(s.resolution, options_.max_buffered);
  switch (mirror_->apply(s)) {
    case MapMirror::SnapshotResult::kApplied:
      heard_ = true;
      if (on_reset_) on_reset_();
      break;
    case MapMirror::SnapshotResult::kIgnored:
      heard_ = true;  // the mirror is at least as new
      break;
    case MapMirror::SnapshotResult::kRejected:
      break;
  }
}

void MapClient::maybe_request(int64_t utime) {
  const bool needed = !mirror_ || !heard_ || mirror_->needs_snapshot();
  if (!needed) return;
  const int64_t interval = static_cast<int64_t>(std::llround(options_.request_interval_s * 1e6));
  if (outstanding_ && utime >= last_request_utime_ && utime - last_request_utime_ < interval) return;
  send_request(utime);
}

void MapClient::send_request(int64_t utime) {
  node_.publish(ch::MAP_REQUEST, request_message(requester_, mirror_ && heard_ ? mirror_->seq() : -1, utime));
  ++counters_.requests;
  outstanding_ = true;
  last_request_utime_ = utime;
}

}  // namespace semx::map
