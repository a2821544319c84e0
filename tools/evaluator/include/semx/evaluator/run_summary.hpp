// Everything a run folder records about one run: what was run (RunInfo), the paper's metrics
// and the coverage over time. Built by Evaluation::summary(); written by run_folder.hpp.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "semx/core/time_split.hpp"
#include "semx/evaluator/run_metrics.hpp"

namespace semx::evaluator {

// What was run, recorded as given on the command line (planner: from PLANNER_STATUS when empty).
struct RunInfo {
  std::string world;       // name (env1) or file stem
  std::string world_path;  // the world file
  std::string planner;     // semantic-dep, dep, aep, nbv, ...
  std::optional<int64_t> seed;
  std::optional<int64_t> samples;  // the planner's sampling density (paper Table II)
  std::string source = "live";     // "live" (semx-evaluator) or "log" (semx-eval)
};

// A process of the set that came back during the run (its NODE_STATUS showed a higher restart
// count or another pid): the run was disturbed, and its figures are not an undisturbed run's.
struct NodeRestart {
  std::string node;
  double t_s = 0.0;  // message time when it was heard back
  int restarts = 0;  // the launcher's count after this restart (0: the pid changed without one)
};

struct RunSummary {
  RunInfo info;
  // The paper's metrics.
  double time_f_s = 0.0;
  double distance_m = 0.0;
  double coverage_pct = 0.0;
  std::optional<double> time_r_s;  // null when the threshold was never reached
  std::optional<double> time_95_s;  // likewise, at 95 %
  std::optional<double> time_settled_s;  // coverage within 0.5 points of its final value
  std::optional<double> end_game_s;      // time_f_s - time_settled_s
  // The same over the objects' surfaces (coverage_tracker.hpp): what semantic-dep is for.
  double object_coverage_pct = 0.0;
  std::optional<double> time_o_s;
  int64_t collisions = 0;
  // False when the run lost or mixed messages (Evaluation::mark_invalid): its figures are not the
  // ones the seed gives, and the bench leaves it out of its tables.
  bool valid = true;
  std::string invalid_reason;
  double wall_s = 0.0;  // wall-clock s from the first SIM_CLOCK, ODOMETRY or MAP_UPDATE to the end
  // Context.
  std::string termination;             // to_string(Termination)
  std::string planner_state;           // last PLANNER_STATUS state, "none" if never heard
  std::string planner_reason;          // its reason text
  double sim_s = 0.0;                  // last message time, s
  double realtime_factor = 0.0;        // sim_s / wall_s (0 when wall_s is 0)
  std::optional<double> time_limit_s;  // null when none
  double coverage_threshold_pct = 85.0;
  double object_threshold_pct = 75.0;
  double resolution_m = 0.0;
  int64_t target_voxels = 0;
  int64_t covered_voxels = 0;
  int64_t object_voxels = 0;  // the objects' surface voxels in the target set
  int64_t map_seq = 0;  // last map sequence number applied
  std::vector<NodeRestart> restarts;  // empty: an undisturbed run
  std::vector<CoverageSample> coverage;
  std::vector<Eigen::Vector3d> trajectory;
  // Where the time went: new space, revisits, turns, hover, end game (time_split.json/.png).
  core::TimeSplitResult time_split;
};

}  // namespace semx::evaluator
