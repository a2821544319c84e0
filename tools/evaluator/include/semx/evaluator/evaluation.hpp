// One run's evaluation: the world's ground truth, the coverage tracker and the metrics, fed by
// events (map deltas and snapshots, odometry, collisions, planner states, the episode's end)
// in message time. The live evaluator node and the log evaluator drive the same object, so a
// run and its recorded log give the same figures.
//
//   Evaluation ev(world, options);
//   ev.on_map_delta(delta, mirror.grid());      // after the mirror applied it
//   ev.on_odometry(utime, p); ...
//   if (auto why = ev.due(now)) ev.finish(*why, now, wall_s);
//   RunSummary s = ev.summary();                // -> write_run_folder(...)
//
// Ending: the planner's DONE at time u ends the run at the first time checked after u (so the
// map updates up to u are in); the time limit ends it at the first time checked >= the limit;
// on_episode_end() ends it at once. Events after the end are ignored.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>
#include <optional>
#include <string>

#include "semx/core/time_split.hpp"
#include "semx/core/byte_io.hpp"
#include "semx/evaluator/coverage_tracker.hpp"
#include "semx/evaluator/run_metrics.hpp"
#include "semx/evaluator/run_summary.hpp"
#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/simulator/world.hpp"

namespace semx::evaluator {

struct EvaluationOptions {
  RunInfo info;               // world name/path, planner, seed, samples (recorded as given)
  double time_limit_s = 0.0;  // 0: none
  double resolution = 0.1;    // ground truth built at start; rebuilt if the map's differs
  MetricsOptions metrics;
};

class Evaluation {
 public:
  Evaluation(simulator::World world, EvaluationOptions options);

  const EvaluationOptions& options() const { return options_; }
  const simulator::World& world() const { return world_; }

  // ---- map ----
  // After the map applied `delta`; `grid_after` is the whole map then (used only when the
  // resolution changed and the ground truth had to be rebuilt).
  void on_map_delta(const map::MapDelta& delta, const map::StateGrid& grid_after);
  // After a snapshot replaced the map (stamped `utime`; `seq`: the map's sequence, if known).
  void on_map_reset(const map::StateGrid& grid, int64_t utime, int64_t seq = -1);

  // ---- vehicle, planner, simulator ----
  // `yaw` (rad) for the time split's turns; not finite: no turn is counted.
  void on_odometry(int64_t utime, const Eigen::Vector3d& position, double yaw = std::nan(""));
  void on_collision(int64_t utime, int64_t running_count);
  void on_planner_status(int64_t utime, const std::string& planner, PlannerState state,
                         const std::string& reason = "");
  // Ends the run now (kEpisodeEnd at utime).
  void on_episode_end(int64_t utime, double wall_s);

  // ---- the set's processes ----
  // The NODE_STATUS of `node` (its pid and the launcher's restart count) at message time `utime`:
  // a higher count, or another pid with the same count, than last heard is a restart (a node
  // first heard with a count above 0 came back before this evaluator heard it).
  void on_node_status(const std::string& node, int pid, int restarts, int64_t utime);
  const std::vector<NodeRestart>& restarts() const { return restarts_; }

  // ---- time ----
  // The reason the run should end if message time has reached `utime`, if any.
  std::optional<Termination> due(int64_t utime) const;
  // Message time moved to `utime` (takes coverage samples).
  void advance(int64_t utime);
  void finish(Termination why, int64_t utime, double wall_s);
  bool finished() const { return metrics_.finished(); }

  // ---- state ----
  const RunMetrics& metrics() const { return metrics_; }
  // The ground truth exists from the constructor on (at options.resolution, then the map's).
  const CoverageTracker& tracker() const { return *tracker_; }
  const simulator::GroundTruth& ground_truth() const { return tracker_->ground_truth(); }
  std::shared_ptr<const simulator::GroundTruth> ground_truth_ptr() const { return gt_; }
  const std::string& planner() const { return planner_; }
  PlannerState planner_state() const { return metrics_.planner_state(); }
  // Map updates seen (deltas applied, resets).
  int64_t map_deltas() const { return map_deltas_; }
  int64_t map_resets() const { return map_resets_; }

  // The run's figures are not the ones an exact run gives (messages lost on the way, map gaps):
  // written as "valid": false with the reasons, and left out of the bench's tables.
  void mark_invalid(const std::string& reason);
  bool valid() const { return invalid_reasons_.empty(); }

  RunSummary summary() const;

  // ---- saved state (semx-evaluator's --state journal) ----
  using Saved = RunMetrics::Saved;
  // One journal record (RunMetrics::save, plus the planner, map and restart records).
  void save(core::ByteWriter& w, Saved& saved) const;
  // Applies one record; throws std::runtime_error (or std::out_of_range when it is cut short).
  void restore(core::ByteReader& r);

 private:
  // Rebuilds the ground truth when the map's resolution is not the tracker's; true if it did.
  bool ensure_resolution(double resolution);
  void note_coverage(int64_t utime);

  simulator::World world_;
  EvaluationOptions options_;
  std::shared_ptr<const simulator::GroundTruth> gt_;
  std::unique_ptr<CoverageTracker> tracker_;
  RunMetrics metrics_;
  core::TimeSplit time_split_;
  std::string planner_;
  std::string planner_reason_;
  int64_t map_deltas_ = 0;
  int64_t map_resets_ = 0;
  int64_t map_seq_ = 0;
  double wall_s_ = 0.0;
  std::vector<std::string> invalid_reasons_;
  struct NodeSeen {
    int pid = 0;
    int restarts = 0;
  };
  std::map<std::string, NodeSeen> nodes_;
  std::vector<NodeRestart> restarts_;
};

}  // namespace semx::evaluator
