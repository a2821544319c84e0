// semx-evaluator's LCM side: an Evaluation fed from the bus. It keeps the mapper's map with a
// MapClient (deltas, snapshots on gaps), integrates ODOMETRY, counts SIM_EVENT COLLISIONs,
// follows PLANNER_STATUS, prints a progress line every `progress_s` of simulated time, and ends
// the run on the planner's DONE, the simulator's EPISODE_END or the time limit: it then writes the
// run folder (metrics.json, metrics.csv, coverage.csv, coverage.png, map.png), prints the
// metrics table and stops the node.
//
// Time: the run's decisions are taken in the SIM_CLOCK tick handler (after the MapClient applied
// the map messages held for the tick), so a lockstep evaluator (--lockstep: MapClient applies on
// ticks) gives the same figures every run. Without any SIM_CLOCK (tests, replays of partial logs),
// each message's utime is the time.
#pragma once

#include <memory>
#include <map>
#include <string>
#include <vector>

#include "map_client.hpp"
#include "semx/evaluator/evaluation.hpp"
#include "semx/evaluator/run_overlays.hpp"
#include "semx/runtime/node.hpp"
#include "semx/runtime/state_file.hpp"

namespace semx::evaluator {

struct EvaluatorNodeOptions {
  EvaluationOptions evaluation;
  std::string out_dir;     // run folder; "" writes nothing
  double progress_s = 10;  // simulated seconds between progress lines; 0: none
  bool print = true;       // progress lines and the final table on stdout
  // A journal of the run's state, appended every coverage sample (empty: none), and whether to
  // go on from what it holds (a restart after a crash): the series, distance, collisions and
  // timestamps come back from it, the map from the mapper's snapshot (docs/launch.md, "When a
  // process dies").
  std::string state_path;
  bool resume = false;
};

class EvaluatorNode {
 public:
  // `node` must outlive this object.
  EvaluatorNode(runtime::Node& node, simulator::World world, EvaluatorNodeOptions options);
  EvaluatorNode(const EvaluatorNode&) = delete;
  EvaluatorNode& operator=(const EvaluatorNode&) = delete;

  // Spins until the run ended (or a signal stopped it: the run then ends as "stopped"), writes
  // the run folder and prints the table. Returns 0, or 1 when the folder could not be written.
  int run();

  // Ends the run now with `why` (run() does it on a signal), writes the folder, prints the table
  // and stops the node. Returns false when writing failed (the message went to stderr).
  bool finish(Termination why);

  bool finished() const { return evaluation_.finished(); }
  const Evaluation& evaluation() const { return evaluation_; }
  const map::MapClient& map() const { return map_; }
  const std::vector<std::string>& written() const { return written_; }
  bool write_failed() const { return write_failed_; }
  // Journal records restored at start (0: a fresh run).
  size_t restored_records() const { return restored_records_; }

 private:
  void on_tick(int64_t tick, int64_t utime);
  // For messages when no SIM_CLOCK has been heard: their utime is the time.
  void message_time(int64_t utime);
  void end_if_due(int64_t utime);
  void progress(int64_t utime);
  void note_wall();
  double wall_s() const;
  void finish_at(Termination why, int64_t utime);
  void write_folder();
  void open_state();
  void save_state();

  runtime::Node& node_;
  EvaluatorNodeOptions options_;
  Evaluation evaluation_;
  map::MapClient map_;
  double wall_start_ = -1;
  double wall_end_ = -1;
  double next_progress_s_ = 0;
  std::vector<std::string> written_;
  bool write_failed_ = false;
  RoadmapOverlay roadmap_;              // the planner's last ROADMAP
  std::vector<RegionOverlay> regions_;  // the last SEMANTIC_REGIONS
  // Each node's messages lost for good, from its NODE_STATUS (and this node's own): a run where
  // any were is not the seed's run.
  std::map<std::string, int64_t> lost_;
  void check_validity();
  std::unique_ptr<runtime::StateJournal> journal_;
  Evaluation::Saved saved_;
  size_t saved_samples_ = 0;
  size_t restored_records_ = 0;
  double wall_start_epoch_ = -1;  // system clock at wall_start_, which a restart keeps counting from
};

}  // namespace semx::evaluator
