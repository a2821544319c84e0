#include "mapper_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
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

// Whether due() would say yes, without scheduling anything.
bool would_be_due(int64_t now, int64_t next, double period_s) {
  return period_s > 0 && (next < 0 || now >= next);
}

constexpr uint32_t kJournalKind = runtime::state_kind("MAPJ");

std::string journal_path(const std::string& checkpoint) { return checkpoint + ".journal"; }

template <class T>
std::vector<uint8_t> encode(const T& m) {
  const int size = m.getEncodedSize();
  std::vector<uint8_t> bytes(static_cast<size_t>(std::max(size, 0)));
  if (size > 0 && m.encode(bytes.data(), 0, size) != size) bytes.clear();
  return bytes;
}

}  // namespace

MapperNode::MapperNode(runtime::Node& node, const MapperConfig& config, MapperNodeOptions options)
    : node_(node), mapper_(config), options_(std::move(options)), gate_(config.integration.frame_period_s) {
  checkpoint_path_ = options_.checkpoint_path.empty() ? config.checkpoint.path : options_.checkpoint_path;
  restore_checkpoint();
  // Frames that are not due are dropped from their bytes' utime, before the 0.6 MB image is
  // validated and decoded.
  node_.skip_unless(ch::CAMERA_DEPTH, [this](int64_t utime) {
    if (gate_.due(utime)) return true;
    ++counters_.frames_skipped;
    return false;
  });
  node_.subscribe<semx::depth_image_t>(
      ch::CAMERA_DEPTH, [this](const semx::depth_image_t& m) { on_depth(m); },
      [this](const semx::depth_image_t& m) { return accept_depth(m); });
  node_.subscribe<semx::odometry_t>(
      ch::ODOMETRY, [this](const semx::odometry_t& m) { on_odometry(m); }, &accept_odometry);
  node_.subscribe<semx::map_request_t>(
      ch::MAP_REQUEST, [this](const semx::map_request_t& m) { on_request(m); }, &map::accept_request);
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  node_.on_quiet_until([this](int64_t utime) { return quiet_until(utime); });
}

MapperNode::~MapperNode() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  work_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
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
  int64_t base_seq = 0;
  if (!fs::exists(path, ec)) {
    startup_note_ = "no checkpoint at " + checkpoint_path_ + " yet; one is written every " +
                    std::to_string(mapper_.config().checkpoint.period) + " s of simulation time";
  } else {
    try {
      const CheckpointInfo info = mapper_.load_checkpoint(checkpoint_path_);
      base_seq = info.seq;
      checkpoint_seq_ = mapper_.seq();
      startup_note_ = "restored " + checkpoint_path_ + " (seq " + std::to_string(info.seq) + ", " +
                      std::to_string(info.blocks) + " blocks, " +
                      std::to_string(mapper_.map().grid().known_voxels()) + " known voxels)";
    } catch (const MapIoError& e) {
      if (!options_.ignore_bad_checkpoint) {
        throw MapIoError(std::string(e.what()) + " (--ignore-bad-checkpoint starts with an empty map instead)");
      }
      const std::string bad = checkpoint_path_ + ".bad";
      fs::rename(path, bad, ec);
      startup_note_ = std::string("ignored the unreadable checkpoint: ") + e.what() + "; " +
                      (ec ? "could not move it aside (" + ec.message() + ")" : "moved to " + bad) +
                      "; starting with an empty map";
      fs::remove(journal_path(checkpoint_path_), ec);  // its deltas continue that map, not an empty one
    }
  }
  if (const int64_t n = replay_journal(base_seq); n > 0) {
    // The journal's deltas are in the map now: a checkpoint holds them, and loading it back
    // makes the sequence jump past every delta sent, so each client resynchronises by snapshot.
    mapper_.save_checkpoint(checkpoint_path_, now_);
    const CheckpointInfo info = mapper_.load_checkpoint(checkpoint_path_);
    checkpoint_seq_ = mapper_.seq();
    startup_note_ += "; replayed " + std::to_string(n) + " map updates from " + journal_path(checkpoint_path_) +
                     " (to seq " + std::to_string(info.seq) + ")";
  }
  if (mapper_.seq() > 0) startup_note_ += "; updates continue at seq " + std::to_string(mapper_.seq() + 1);
  journal_ = std::make_unique<runtime::StateJournal>(journal_path(checkpoint_path_), kJournalKind, true);
}

int64_t MapperNode::replay_journal(int64_t checkpoint_seq) {
  const std::string file = journal_path(checkpoint_path_);
  std::vector<std::vector<uint8_t>> records;
  try {
    records = runtime::read_state_journal(file, kJournalKind);
  } catch (const runtime::StateFileError& e) {
    startup_note_ += std::string("; ignored ") + e.what();
    return 0;
  }
  int64_t replayed = 0, last = checkpoint_seq;
  for (const auto& rec : records) {
    semx::map_update_t m;
    map::MapDelta d;
    try {
      if (m.decode(rec.data(), 0, static_cast<int>(rec.size())) != static_cast<int>(rec.size())) break;
    } catch (const std::exception&) {
      break;
    }
    if (!map::accept_update(m) || !map::from_message(m, d)) break;
    if (d.seq <= checkpoint_seq) continue;  // written before the checkpoint that holds it
    if (d.seq != last + 1) break;           // not this map's next delta: stop where it stops
    mapper_.replay_delta(d);
    last = d.seq;
    if (!have_time_ || d.utime > now_) now_ = d.utime;
    have_time_ = true;
    ++replayed;
  }
  return replayed;
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

bool MapperNode::pipelined() const {
  // A lockstep node's frames before the first tick too: the tick brings their odometry.
  return mapper_.config().streaming.lockstep_delay > 0 &&
         (node_.clock().started() ? node_.clock().mode() == runtime::ClockMode::kLockstep
                                  : node_.clock().participant());
}

void MapperNode::on_depth(const semx::depth_image_t& m) {
  gate_.taken(m.utime);
  auto job = std::make_shared<Job>();
  job->now = have_time_ ? std::max(now_, m.utime) : m.utime;
  if (!pipelined()) {
    // Around the vehicle; before the first odometry, around the camera.
    job->center = vehicle_ ? *vehicle_ : Eigen::Vector3d(decoded_.T_world_optical.translation());
    std::swap(job->frame, decoded_);  // borrowed: decoded_ keeps its buffer for the next frame
    compute(*job);
    finish(*job);
    std::swap(job->frame, decoded_);
    periodic();
    return;
  }
  job->frame = std::move(decoded_);
  in_flight_.push_back(job);  // started by the next tick (start_jobs)
}

void MapperNode::start_jobs() {
  bool any = false;
  for (const auto& job : in_flight_) {
    if (job->started) continue;
    job->center = vehicle_ ? *vehicle_ : Eigen::Vector3d(job->frame.T_world_optical.translation());
    job->started = any = true;
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(job);
  }
  if (!any) return;
  if (!worker_.joinable()) worker_ = std::thread([this] { worker_loop(); });
  work_cv_.notify_one();
}

void MapperNode::compute(Job& job) {
  job.result = mapper_.integrate(job.frame.frame());
  if (!job.result.report.accepted) return;
  job.update_bytes = encode(map::to_message(job.result.delta));
  const MapperConfig& cfg = mapper_.config();
  if (cfg.esdf.enabled &&
      (cfg.streaming.esdf_period <= 0 || due(job.now, next_esdf_, cfg.streaming.esdf_period))) {
    job.esdf = true;
    if (mapper_.update_esdf(job.center)) {
      job.esdf_recomputed = true;
      job.esdf_ms = mapper_.esdf_ms();
    }
    job.esdf_bytes = encode(map::to_message(mapper_.esdf(), job.frame.utime));
  }
}

void MapperNode::finish(Job& job) {
  ++counters_.frames_received;
  const FrameResult& r = job.result;
  counters_.integrate_ms += r.integrate_ms;
  if (!r.report.accepted) {
    ++counters_.frames_rejected;
    if (!options_.quiet && worth_logging(counters_.frames_rejected)) {
      std::cerr << node_.name() << ": depth frame at utime " << job.frame.utime
                << " rejected: " << r.report.error << " (" << counters_.frames_rejected << " so far)\n";
    }
    return;
  }
  if (!have_time_ || job.frame.utime > now_) now_ = job.frame.utime;
  have_time_ = true;
  if (journal_) {
    try {
      journal_->append(job.update_bytes);
    } catch (const runtime::StateFileError& e) {
      std::cerr << node_.name() << ": " << e.what() << " (map updates are no longer journaled)\n";
      journal_.reset();
    }
  }
  node_.publish_raw(ch::MAP_UPDATE, job.update_bytes.data(), job.update_bytes.size());
  ++counters_.updates;
  if (job.esdf) {
    if (job.esdf_recomputed) {
      ++counters_.esdf_recomputes;
      counters_.esdf_ms += job.esdf_ms;
    }
    node_.publish_raw(ch::ESDF_LOCAL, job.esdf_bytes.data(), job.esdf_bytes.size());
    ++counters_.esdfs;
  }
}

void MapperNode::worker_loop() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_cv_.wait(lock, [this] { return quit_ || !queue_.empty(); });
      if (queue_.empty()) return;  // quitting, and nothing left to do
      job = queue_.front();
      queue_.pop_front();
    }
    compute(*job);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job->done = true;
    }
    done_cv_.notify_all();
  }
}

void MapperNode::publish_done(int64_t up_to_utime) {
  start_jobs();
  while (!in_flight_.empty() && in_flight_.front()->frame.utime <= up_to_utime) {
    const std::shared_ptr<Job> job = in_flight_.front();
    {
      std::unique_lock<std::mutex> lock(mutex_);
      done_cv_.wait(lock, [&] { return job->done; });
    }
    in_flight_.pop_front();
    finish(*job);
  }
}

void MapperNode::flush_frames() { publish_done(std::numeric_limits<int64_t>::max()); }

void MapperNode::flush_without_clock() {
  node_.release_promise();
  flush_frames();
}

bool MapperNode::periodic_due() const {
  const StreamingParams& st = mapper_.config().streaming;
  const double cp = mapper_.config().checkpoint.period;
  return would_be_due(now_, next_snapshot_, st.snapshot_period) ||
         would_be_due(now_, next_stats_, st.stats_period) ||
         (!checkpoint_path_.empty() && cp > 0 && next_checkpoint_ >= 0 && now_ >= next_checkpoint_);
}

void MapperNode::on_odometry(const semx::odometry_t& m) {
  vehicle_ = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
}

void MapperNode::on_request(const semx::map_request_t& /*m*/) {
  ++counters_.requests;
  const bool lockstep = node_.clock().started() && node_.clock().mode() == runtime::ClockMode::kLockstep;
  if (!lockstep) {
    flush_frames();
    publish_snapshot();
    return;
  }
  request_pending_ = true;
}

void MapperNode::on_tick(int64_t tick, int64_t utime) {
  if (tick == 0 && have_time_ && utime < now_) {
    // The clock restarted (a new episode): the map stays, the schedules start again.
    flush_frames();
    now_ = utime;
    next_stats_ = next_snapshot_ = next_esdf_ = next_checkpoint_ = -1;
  }
  if (!have_time_ || utime > now_) now_ = utime;
  have_time_ = true;
  start_jobs();
  // A request that came while this node had promised quiet waits for the promised tick.
  const bool answer = request_pending_ && node_.may_publish();
  if (!in_flight_.empty()) {
    // Outputs that read the map describe the map of the last MAP_UPDATE sent: publish every
    // frame first. Otherwise only the frames whose delay has passed.
    if (answer || periodic_due()) {
      flush_frames();
    } else {
      publish_done(utime - period_us(mapper_.config().streaming.lockstep_delay));
    }
  }
  if (answer) publish_snapshot();
  periodic();
}

int64_t MapperNode::quiet_until(int64_t utime) const {
  if (request_pending_) return utime;
  const StreamingParams& st = mapper_.config().streaming;
  // A frame is published lockstep_delay after its utime (in its own handler when not pipelined).
  const int64_t delay = pipelined() ? period_us(st.lockstep_delay) : 0;
  const int64_t frame = gate_.next_due();
  if (frame == std::numeric_limits<int64_t>::min()) return utime;
  int64_t q = frame + delay;
  if (!in_flight_.empty()) q = std::min(q, in_flight_.front()->frame.utime + delay);
  for (const auto& [next, period] :
       {std::pair{next_snapshot_, st.snapshot_period}, {next_stats_, st.stats_period}}) {
    if (period > 0) q = std::min(q, next < 0 ? utime : next);
  }
  const double cp = mapper_.config().checkpoint.period;
  if (!checkpoint_path_.empty() && cp > 0) q = std::min(q, next_checkpoint_ < 0 ? utime : next_checkpoint_);
  return q;
}

bool MapperNode::clock_silent() const {
  return std::chrono::steady_clock::now() - last_heard_ >=
         std::chrono::duration<double>(options_.request_grace_s);
}

void MapperNode::poll_wall() {
  // Silence (measured from the last message, the request being one), not the time since the
  // request: on a loaded machine the ticks up to the promised one can take longer than any fixed
  // wait, and answering before them gave runs of the same seed different maps.
  if (request_pending_ && clock_silent()) {
    flush_without_clock();
    publish_snapshot();
  }
}

void MapperNode::publish_snapshot() {
  flush_frames();  // the worker owns the map while frames are in flight
  node_.publish(ch::MAP_SNAPSHOT, map::to_message(mapper_.snapshot(now_)));
  ++counters_.snapshots;
  request_pending_ = false;
}

void MapperNode::publish_stats() {
  flush_frames();
  map::MapStats s = mapper_.stats(true);
  s.frames_rejected += frames_malformed();
  node_.publish(ch::MAP_STATS, map::to_message(s, now_));
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
  flush_frames();
  if (checkpoint_path_.empty() || mapper_.seq() == checkpoint_seq_) return false;
  try {
    mapper_.save_checkpoint(checkpoint_path_, now_);
    checkpoint_seq_ = mapper_.seq();
    ++counters_.checkpoints;
    checkpoint_failing_ = false;
    if (journal_) journal_->clear();  // the checkpoint holds every delta journaled
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
  last_heard_ = std::chrono::steady_clock::now();
  while (!node_.stopped()) {
    const int got = node_.spin_once(100);
    if (got < 0) {
      node_.set_state(runtime::NodeState::kFailed, "LCM provider failed");
      rc = 1;
      break;
    }
    if (got > 0) last_heard_ = std::chrono::steady_clock::now();
    // Frames in flight and a silent clock (request_grace_s): it stopped (the simulator ended), so
    // no tick will publish them. Wall time, not a count of empty spins: every fragment of a depth
    // frame that arrives alone ends a spin without a message, and on a loaded machine ten of
    // them came within a tick, so frames went out before their tick and runs of one seed
    // differed (env3, semantic-dep, seed 5: Time_r 53.7 s against 69.3 s).
    if (!in_flight_.empty() && clock_silent()) flush_without_clock();
    poll_wall();
  }
  flush_without_clock();
  checkpoint_now();
  if (rc == 0)
    node_.set_state(runtime::NodeState::kStopping, runtime::shutdown_requested() ? "signal" : "stopped");
  return rc;
}

}  // namespace semx::mapper
