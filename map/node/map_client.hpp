// The map client for any process that needs the mapper's map (planner, semantics, tools): given
// a runtime::Node, it subscribes MAP_UPDATE and MAP_SNAPSHOT, keeps a MapMirror, and asks for a
// MAP_SNAPSHOT (MAP_REQUEST) at start and whenever the mirror finds a gap in the sequence, so the
// mirror converges to the mapper's map exactly whatever messages are lost.
//
//   runtime::Node node(options);
//   map::MapClient client(node);                // resolution from the mapper's first message
//   ... node.spin_once(...) ...
//   if (client.in_sync()) client.mirror().is_frontier(k);
//
// Requests: one at construction; then, while the mirror waits for a snapshot (a gap) or has not
// heard from the mapper, one whenever no request is outstanding, and again every
// request_interval_s of message time while the mapper does not answer. Message time is the
// node's SIM_CLOCK time or the newest map message's utime, whichever is later.
//
// Determinism (DESIGN.md §3): in LOCKSTEP a delta for the frame of tick k reaches this process
// some time before SIM_CLOCK(k + 1), but not at a fixed point relative to SIM_CLOCK(k). With
// Apply::kOnTick (the default for lockstep participants) messages are held back and applied in
// the tick handler: at tick k + 1 everything with utime < t(k + 1), in arrival order; requests go
// out from the tick handler too. The mirror is then the same at every tick of every run.
#pragma once

#include <semx/map_snapshot_t.hpp>
#include <semx/map_update_t.hpp>

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include "semx/map/map_mirror.hpp"
#include "semx/runtime/node.hpp"

namespace semx::map {

struct MapClientOptions {
  // Voxel size the client expects, m; 0: adopt the mapper's from its first message (and follow
  // a snapshot of another resolution, e.g. after the mapper restarted with another config).
  double resolution = 0.0;
  // Message time between MAP_REQUESTs while one is outstanding and unanswered.
  double request_interval_s = 0.5;
  enum class Apply {
    kAuto,         // kOnTick for a lockstep participant (NodeOptions::lockstep), else kImmediately
    kImmediately,  // apply each message in its handler (lowest latency)
    kOnTick,       // hold messages back and apply them in the tick handler (deterministic)
  };
  Apply apply = Apply::kAuto;
  std::string requester;      // MAP_REQUEST.requester; default: the node's name
  size_t max_buffered = 256;  // deltas a mirror keeps while waiting for a snapshot
  bool quiet = false;         // no log line for a resolution mismatch
};

class MapClient {
 public:
  struct Counters {
    int64_t updates = 0;                // MAP_UPDATEs received (valid ones; malformed are in NODE_STATUS)
    int64_t snapshots = 0;              // MAP_SNAPSHOTs received
    int64_t requests = 0;               // MAP_REQUESTs sent
    int64_t resolution_mismatches = 0;  // messages of another resolution than the mirror's
  };

  // Subscribes on `node` (which must outlive this) and sends the first MAP_REQUEST.
  explicit MapClient(runtime::Node& node, MapClientOptions options = {});
  MapClient(const MapClient&) = delete;
  MapClient& operator=(const MapClient&) = delete;

  // False only while the resolution is still to be adopted from the mapper.
  bool has_mirror() const { return mirror_ != nullptr; }
  // Throws std::logic_error before has_mirror().
  const MapMirror& mirror() const;
  // The mirror holds the mapper's map as of mirror().seq(): it has heard from the mapper (a
  // snapshot, or deltas from seq 1 on) and is not waiting for a snapshot.
  bool in_sync() const { return mirror_ && heard_ && !mirror_->needs_snapshot(); }
  int64_t seq() const { return mirror_ ? mirror_->seq() : 0; }
  const Counters& counters() const { return counters_; }
  MapClientOptions::Apply apply_mode() const { return apply_; }

  // Called after each delta applied in sequence (not for those a snapshot brings along).
  void on_delta(std::function<void(const MapDelta&)> fn) { on_delta_ = std::move(fn); }
  // Called after a snapshot replaced the mirror's content (anything may have changed).
  void on_reset(std::function<void()> fn) { on_reset_ = std::move(fn); }

  // The tick handler (registered with the node; public for tests).
  void on_tick(int64_t tick, int64_t utime);

 private:
  struct Held {
    bool snapshot = false;
    int64_t utime = 0;
    MapDelta delta;
    MapSnapshot snap;
  };

  void on_update(const semx::map_update_t& m);
  void on_snapshot(const semx::map_snapshot_t& m);
  void apply(const Held& h);
  void apply_delta(const MapDelta& d);
  void apply_snapshot(const MapSnapshot& s);
  void hold(Held h);
  void maybe_request(int64_t utime);
  void send_request(int64_t utime);
  int64_t now() const;

  runtime::Node& node_;
  MapClientOptions options_;
  MapClientOptions::Apply apply_;
  std::string requester_;
  std::unique_ptr<MapMirror> mirror_;
  bool heard_ = false;
  bool outstanding_ = false;  // a request was sent and no snapshot has come since
  int64_t last_request_utime_ = 0;
  int64_t latest_utime_ = 0;
  int64_t last_tick_utime_ = -1;
  std::deque<Held> held_;
  Counters counters_;
  std::function<void(const MapDelta&)> on_delta_;
  std::function<void()> on_reset_;
};

}  // namespace semx::map
