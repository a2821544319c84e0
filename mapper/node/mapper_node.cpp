#include "mapper_node.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <system_error>

#include "semx/runtime/channels.hpp"

namespace semx::mapper {

namespace ch = semx::channels;
namespace fs = std::filesystem;

namespace {

// The 1st..5th, 10th, 100th, ... occurrence (as the Node logs dropped messages).
bool worth_logging(int64_t n) {
  if (n <= 5) return true;
  while (n % 10 == 0) n /= 10;
  return n == 1;
}

int64_t period_us(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

// True when a periodic output is due at `now` (period > 0), and schedules the next one. The
// first is due at once when `next` < 0; a late one does not try to catch up.
bool due(int64_t now, int64_t& next, double period_s) {
  if (!(period_s > 0)) return false;
  const int64_t p = period_us(period_s);
  if (next >= 0 && now < next) return false;
  next = (next < 0 || now - next >= p) ? now + p : next + p;
  return true;
}

}  // namespace

MapperNode::MapperNode(runtime::Node& node, const MapperConfig& config, MapperNodeOptions options)
    : node_(node), mapper_(config), options_(std::move(options)) {
  checkpoint_path_ = options_.checkpoint_path.empty() ? config.checkpoint.path : options_.checkpoint_path;
  restore_checkpoint();
  node_.subscribe<semx::depth_image_t>(
      ch::CAMERA_DEPTH, [this](const semx::depth_image_t& m) { on_depth(m); },
      [this](const semx::depth_image_t& m) { return accept_depth(m); });
  node_.subscribe<semx::odometry_t>(
      ch::ODOMETRY, [this](const semx::odometry_t& m) { on_odometry(m); }, &accept_odometry);
  node_.subscribe<semx::map_request_t>(
      ch::MAP_REQUEST, [this](const semx::map_request_t& m) { on_request(m); }, &accept_request);
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
}

void MapperNode::restore_checkpoint() {
  if (checkpoint_path_.empty()) {
    startup_note_ = "no checkpoint file configured";
    return;
  }
  const fs::path path(checkpoint_path_);
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw runtime::ConfigError("checkpoint " + checkpoint_path_ + ": directory " + dir.string() +
                               " does not exist");
  }
  if (!fs::exists(path, ec)) {
    startup_note_ = "no checkpoint at " + checkpoint_path_ + " yet; one is written every " +
                    std::to_string(mapper_.config().checkpoint.period) + " s of simulation time";
    return;
  }
  try {
    const CheckpointInfo info = mapper_.load_checkpoint(checkpoint_path_);
    checkpoint_seq_ = mapper_.seq();
    startup_note_ = "restored " + checkpoint_path_ + " (seq " + std::to_string(info.seq) + ", " +
                    std::to_string(info.blocks) + " blocks, " +
                    std::to_string(mapper_.map().grid().known_voxels()) +
                    " known voxels); updates continue at seq " + std::to_string(mapper_.seq() + 1);
  } catch (const MapIoError& e) {
    if (!options_.ignore_bad_checkpoint) {
      throw MapIoError(std::string(e.what()) + " (--ignore-bad-checkpoint starts with an empty map instead)");
    }
    const std::string bad = checkpoint_path_ + ".bad";
    fs::rename(path, bad, ec);
    startup_note_ = std::string("ignored the unreadable checkpoint: ") + e.what() + "; " +
                    (ec ? "could not move it aside (" + ec.message() + ")" : "moved to " + bad) +
                    "; starting with an empty map";
  }
}

int64_t MapperNode::frames_malformed() const {
  const auto it = node_.incoming().find(ch::CAMERA_DEPTH);
  return it == node_.incoming().end() ? 0 : it->second.malformed + it->second.dropped;
}

bool MapperNode::accept_depth(const semx::depth_image_t& m) {
  std::string why = decode_depth(m, decoded_);
  if (why.empty()) why = check_frame(decoded_.frame());
  if (why.empty()) return true;
  if (!options_.quiet && worth_logging(frames_malformed() + 1)) {
    std::cerr << node_.name() << ": depth frame at utime " << m.utime << " dropped: " << why << "\n";
  }
  return false;
}

void MapperNode::on_depth(const semx::depth_image_t& m) {
  ++counters_.frames_received;
  const FrameResult r = mapper_.integrate(decoded_.frame());
  counters_.integrate_ms += r.integrate_ms;
  if (!r.report.accepted) {
    ++counters_.frames_rejected;
    if (!options_.quiet && worth_logging(counters_.frames_rejected)) {
      std::cerr << node_.name() << ": depth frame at utime " << m.utime << " rejected: " << r.report.error
                << " (" << counters_.frames_rejected << " so far)\n";
    }
    return;
  }
  if (!have_time_ || m.utime > now_) now_ = m.utime;
  have_time_ = true;
  node_.publish(ch::MAP_UPDATE, to_message(r.delta));
  ++counters_.updates;

  const MapperConfig& cfg = mapper_.config();
  if (cfg.esdf.enabled &&
      (cfg.streaming.esdf_period <= 0 || due(now_, next_esdf_, cfg.streaming.esdf_period))) {
    // Around the vehicle; before the first odometry, around the camera.
    const Eigen::Vector3d center =
        vehicle_ ? *vehicle_ : Eigen::Vector3d(decoded_.T_world_optical.translation());
    if (mapper_.update_esdf(center)) {
      ++counters_.esdf_recomputes;
      counters_.esdf_ms += mapper_.esdf_ms();
    }
    node_.publish(ch::ESDF_LOCAL, to_message(mapper_.esdf(), m.utime));
    ++counters_.esdfs;
  }
  periodic();
}

void MapperNode::on_odometry(const semx::odometry_t& m) {
  vehicle_ = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
}

void MapperNode::on_request(const semx::map_request_t& /*m*/) {
  ++counters_.requests;
  const bool lockstep = node_.clock().started() && node_.clock().mode() == runtime::ClockMode::kLockstep;
  if (!lockstep) {
    publish_snapshot();
    return;
  }
  if (!request_pending_) {
    request_pending_ = true;
    request_since_ = std::chrono::steady_clock::now();
  }
}

void MapperNode::on_tick(int64_t tick, int64_t utime) {
  if (tick == 0 && have_time_ && utime < now_) {
    // The clock restarted (a new episode): the map stays, the schedules start again.
    now_ = utime;
    next_stats_ = next_snapshot_ = next_esdf_ = next_checkpoint_ = -1;
  }
  if (!have_time_ || utime > now_) now_ = utime;
  have_time_ = true;
  if (request_pending_) publish_snapshot();
  periodic();
}

void MapperNode::poll_wall() {
  if (request_pending_ && std::chrono::steady_clock::now() - request_since_ >
                              std::chrono::duration<double>(options_.request_grace_s)) {
    publish_snapshot();
  }
}

void MapperNode::publish_snapshot() {
  node_.publish(ch::MAP_SNAPSHOT, to_message(mapper_.snapshot(now_)));
  ++counters_.snapshots;
  request_pending_ = false;
}

void MapperNode::publish_stats() {
  MapStats s = mapper_.stats(true);
  s.frames_rejected += frames_malformed();
  node_.publish(ch::MAP_STATS, to_message(s, now_));
  ++counters_.stats;
  update_state();
}

void MapperNode::periodic() {
  const StreamingParams& st = mapper_.config().streaming;
  if (due(now_, next_snapshot_, st.snapshot_period)) publish_snapshot();
  if (due(now_, next_stats_, st.stats_period)) publish_stats();
  const double cp = mapper_.config().checkpoint.period;
  if (!checkpoint_path_.empty() && cp > 0) {
    if (next_checkpoint_ < 0) {
      next_checkpoint_ = now_ + period_us(cp);  // the first one a period after start
    } else if (due(now_, next_checkpoint_, cp)) {
      checkpoint_now();
    }
  }
}

bool MapperNode::checkpoint_now() {
  if (checkpoint_path_.empty() || mapper_.seq() == checkpoint_seq_) return false;
  try {
    mapper_.save_checkpoint(checkpoint_path_, now_);
    checkpoint_seq_ = mapper_.seq();
    ++counters_.checkpoints;
    checkpoint_failing_ = false;
    return true;
  } catch (const MapIoError& e) {
    ++counters_.checkpoint_errors;
    checkpoint_failing_ = true;
    if (!options_.quiet && worth_logging(counters_.checkpoint_errors)) {
      std::cerr << node_.name() << ": checkpoint failed: " << e.what() << "\n";
    }
    node_.set_state(runtime::NodeState::kDegraded, std::string("checkpoint failed: ") + e.what());
    return false;
  }
}

void MapperNode::update_state() {
  if (checkpoint_failing_) return;  // keep the failure visible until a checkpoint succeeds
  char detail[160];
  std::snprintf(
      detail, sizeof(detail), "seq %lld, %lld frames (%lld rejected), %.1f m3 known",
      static_cast<long long>(mapper_.seq()), static_cast<long long>(mapper_.frames_integrated()),
      static_cast<long long>(mapper_.frames_rejected() + frames_malformed()),
      static_cast<double>(mapper_.map().grid().known_voxels()) * std::pow(mapper_.map().resolution(), 3));
  node_.set_state(runtime::NodeState::kRunning, detail);
}

int MapperNode::run() {
  if (node_.state() == runtime::NodeState::kStarting)
    node_.set_state(runtime::NodeState::kRunning, "waiting for frames");
  int rc = 0;
  while (!node_.stopped()) {
    if (node_.spin_once(100) < 0) {
      node_.set_state(runtime::NodeState::kFailed, "LCM provider failed");
      rc = 1;
      break;
    }
    poll_wall();
  }
  checkpoint_now();
  if (rc == 0)
    node_.set_state(runtime::NodeState::kStopping, runtime::shutdown_requested() ? "signal" : "stopped");
  return rc;
}

}  // namespace semx::mapper
