// The mapper process around the Mapper library (docs/mapper.md, "Process"):
//
//   subscribes  CAMERA_DEPTH (depth_image_t), ODOMETRY (odometry_t), MAP_REQUEST (map_request_t)
//   publishes   MAP_UPDATE   after every accepted frame (also when nothing changed), in the handler
//               ESDF_LOCAL   after the frame's MAP_UPDATE, around the latest ODOMETRY position
//                            (every frame, or every streaming.esdf_period)
//               MAP_SNAPSHOT every streaming.snapshot_period and on MAP_REQUEST
//               MAP_STATS    every streaming.stats_period
//   writes      the checkpoint every checkpoint.period and on shutdown
//
// Everything runs on message time: the node's time is the latest SIM_CLOCK tick or frame utime,
// and the periodic outputs are due by it, never by the wall clock. Depth frames are decoded and
// checked by the subscription's accept predicate, so a frame that is not a frame counts as
// malformed (NODE_STATUS) and changes nothing.
//
// Determinism in LOCKSTEP: the simulator publishes a tick's frames before SIM_CLOCK(k). With
// streaming.lockstep_delay = 0 the handlers publish MAP_UPDATE/ESDF_LOCAL as they run and the
// periodic outputs run in the tick handler, all before the Node acks k. With a delay d > 0 (the
// default) a frame received while following a LOCKSTEP clock goes to a worker thread at once,
// and the tick handler of the first tick with utime >= frame utime + d waits for it and publishes
// its outputs before the ack: which tick carries them depends on message time only. A tick that
// is due to publish a snapshot, stats, a checkpoint or a requested snapshot first waits for and
// publishes every frame received so far, so those always describe the map of the last published
// MAP_UPDATE. MAP_REQUESTs received while following a LOCKSTEP clock are
// answered in the next tick handler (so every run answers at the same tick); otherwise, or when
// no message at all comes for `request_grace_s` of wall time (the simulator ended), at once.
#pragma once

#include <semx/depth_image_t.hpp>
#include <semx/map_request_t.hpp>
#include <semx/odometry_t.hpp>

#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "map_messages.hpp"
#include "mapper_messages.hpp"
#include "semx/mapper/mapper.hpp"
#include "semx/runtime/frame_gate.hpp"
#include "semx/runtime/node.hpp"
#include "semx/runtime/state_file.hpp"

namespace semx::mapper {

struct MapperNodeOptions {
  // Checkpoint file; empty: config.checkpoint.path. Loaded at construction when it exists, with
  // the deltas published after it (<checkpoint>.journal).
  std::string checkpoint_path;
  // A checkpoint that exists but cannot be loaded: start with an empty map instead of failing
  // (the bad file is renamed to <path>.bad so the next checkpoint does not destroy the evidence).
  bool ignore_bad_checkpoint = false;
  // Wall seconds without any message after which a LOCKSTEP clock counts as stopped (the
  // simulator ended): a pending MAP_REQUEST is answered and frames in flight are published
  // without their tick. A clock that waits for a slow node resends its tick every 0.5 s, so a
  // running one is never this silent.
  double request_grace_s = 1.0;
  bool quiet = false;  // no log lines for malformed or rejected frames
};

class MapperNode {
 public:
  struct Counters {
    int64_t frames_received = 0;  // passed the subscription's checks (decoded, plausible)
    int64_t frames_rejected = 0;  // of which refused by the integrator (e.g. no range overlap)
    int64_t frames_skipped = 0;   // not due (integration.frame_period_s): dropped unread
    int64_t updates = 0;
    int64_t esdfs = 0;
    int64_t snapshots = 0;
    int64_t requests = 0;
    int64_t stats = 0;
    int64_t checkpoints = 0;
    int64_t checkpoint_errors = 0;
    // Wall-clock cost, for the exit summary and monitoring only.
    double integrate_ms = 0.0;  // total in Mapper::integrate
    int64_t esdf_recomputes = 0;
    double esdf_ms = 0.0;  // total in the ESDF recomputes
  };

  // Subscribes on `node` (which must outlive this) and loads the checkpoint when the file
  // exists. Throws MapIoError (naming the file) for a checkpoint that cannot be loaded unless
  // ignore_bad_checkpoint, and runtime::ConfigError for an invalid config or a checkpoint
  // path whose directory does not exist.
  MapperNode(runtime::Node& node, const MapperConfig& config, MapperNodeOptions options = {});
  ~MapperNode();
  MapperNode(const MapperNode&) = delete;
  MapperNode& operator=(const MapperNode&) = delete;

  // Spins the node until shutdown, then writes a last checkpoint; returns the exit code.
  int run();

  // What a SIM_CLOCK tick triggers (public for tests): time moves to `utime`, pending requests
  // are answered and the periodic outputs published when due.
  void on_tick(int64_t tick, int64_t utime);
  // Wall-clock liveness (run() calls it): answers a request that waited too long for a tick.
  void poll_wall();
  // Writes the checkpoint now if there is a path and the map changed since the last one.
  bool checkpoint_now();
  // Waits for the worker and publishes the outputs of every frame received so far (run() does it
  // on exit; lockstep ticks do it when due). Afterwards mapper() is the map of the last MAP_UPDATE.
  void flush_frames();
  // Frames handed to the worker whose outputs are not published yet.
  std::size_t frames_in_flight() const { return in_flight_.size(); }

  // Call flush_frames() first when frames may be in flight (the worker owns the map meanwhile).
  const Mapper& mapper() const { return mapper_; }
  const Counters& counters() const { return counters_; }
  // CAMERA_DEPTH messages dropped before the integrator: malformed bytes, content that is not a
  // frame, or over the node's size limit (also in NODE_STATUS).
  int64_t frames_malformed() const;
  const std::string& checkpoint_path() const { return checkpoint_path_; }
  // What happened to the checkpoint at start-up, for the log ("restored ...", "none yet", ...).
  const std::string& startup_note() const { return startup_note_; }
  int64_t now_utime() const { return now_; }

 private:
  // One frame's work and outputs: computed on the worker (or inline), published on the node's
  // thread.
  struct Job {
    DecodedDepth frame;
    int64_t now = 0;         // node time once the frame is accepted
    Eigen::Vector3d center;  // ESDF window centre (the odometry of the frame's tick)
    bool started = false;    // pipelined: handed to the worker (on the tick after the frame)
    FrameResult result;
    bool esdf = false;  // ESDF_LOCAL goes out with this frame
    bool esdf_recomputed = false;
    double esdf_ms = 0.0;
    std::vector<uint8_t> update_bytes, esdf_bytes;
    bool done = false;  // set by the worker under mutex_
  };

  bool accept_depth(const semx::depth_image_t& m);
  void on_depth(const semx::depth_image_t& m);
  bool pipelined() const;
  void compute(Job& job);  // integrate, ESDF, encode: touches the map, so one thread at a time
  void finish(Job& job);   // counters, log lines, publication
  void publish_done(int64_t up_to_utime);  // in-flight frames with utime <= this, in order
  // Pipelined: hands the frames that came since the last tick to the worker, centred on the
  // vehicle's odometry of now. A frame comes right after its tick's odometry; when that odometry
  // was lost and is sent again, the frame is handled first, and centred on the odometry before,
  // the ESDF differed from a lossless run's. By the tick, the odometry is held.
  void start_jobs();
  bool periodic_due() const;
  // LOCKSTEP: the earliest message time of this node's next output (runtime::Node::on_quiet_until).
  int64_t quiet_until(int64_t utime) const;
  void worker_loop();
  // No tick will come (the simulator ended, or the node stops): drops this node's promise and
  // publishes every frame in flight now.
  void flush_without_clock();
  void on_odometry(const semx::odometry_t& m);
  void on_request(const semx::map_request_t& m);
  void publish_snapshot();
  void publish_stats();
  void periodic();
  void restore_checkpoint();
  // Replays <checkpoint>.journal (the deltas published since the checkpoint) onto the restored
  // map; returns how many.
  int64_t replay_journal(int64_t checkpoint_seq);
  void update_state();

  runtime::Node& node_;
  Mapper mapper_;
  MapperNodeOptions options_;
  std::string checkpoint_path_;
  std::string startup_note_;
  Counters counters_;
  runtime::FrameGate gate_;
  DecodedDepth decoded_;  // written by accept_depth, read by on_depth right after
  std::optional<Eigen::Vector3d> vehicle_;
  int64_t now_ = 0;
  bool have_time_ = false;
  // Next due times (message time, us); -1: at the first opportunity.
  int64_t next_stats_ = -1;
  int64_t next_snapshot_ = -1;
  int64_t next_esdf_ = -1;
  int64_t next_checkpoint_ = -1;
  int64_t checkpoint_seq_ = 0;  // map seq of the last checkpoint written or loaded (0: the empty map)
  bool checkpoint_failing_ = false;
  // Every MAP_UPDATE since the last checkpoint, written before it is published: a mapper killed
  // between checkpoints comes back with every delta its clients were sent.
  std::unique_ptr<runtime::StateJournal> journal_;
  bool request_pending_ = false;
  // When the node last handled a message (wall): the clock's silence is measured from it.
  std::chrono::steady_clock::time_point last_heard_ = std::chrono::steady_clock::now();
  bool clock_silent() const;

  // Pipelined LOCKSTEP frames (streaming.lockstep_delay > 0). in_flight_ is the node thread's
  // list, in arrival order; queue_ what the worker has yet to start. A Job's fields are written
  // by the worker until `done`, then only read by the node thread.
  std::deque<std::shared_ptr<Job>> in_flight_;
  std::deque<std::shared_ptr<Job>> queue_;
  std::mutex mutex_;
  std::condition_variable work_cv_, done_cv_;
  bool quit_ = false;
  std::thread worker_;
};

}  // namespace semx::mapper
