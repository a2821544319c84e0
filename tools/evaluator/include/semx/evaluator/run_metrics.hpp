// The paper's metrics of one exploration run (§IV, DESIGN.md §5), accumulated from events in
// message time (simulation microseconds since the episode started at utime 0):
//
//   Time_f     s until the planner declared DONE; else the time limit or the end of the episode
//              (or the last time seen, when the run was stopped or the log ended);
//   Distance   m, the sum of |p_i - p_(i-1)| over consecutive odometry positions;
//   Coverage   %, the final coverage of the ground truth's target set;
//   Time_r     s, the time of the first map update after which coverage >= 85 % (none if never);
//   Time_95    s, the same at 95 %: how long the last rooms took, which 85 % does not see;
//   Time_settled s, the first map update after which coverage was within 0.5 points of its final
//              value: when the map stopped growing;
//   End game   s, Time_f - Time_settled: how long DONE came after that (the tail a planner flies
//              for nothing: unreachable frontiers, gains that never fall below the threshold);
//   Time_o     s, the first time the objects' surfaces (CoverageTracker's object coverage: the
//              furniture a semantic planner is meant to look at) are 75 % covered: their
//              bottoms and backs keep the whole run below 90 % (env3 ends at 86 %);
//   collisions the number of COLLISION events (or the simulator's running count, if higher:
//              events the evaluator missed still count);
//   the coverage over time, sampled every `sample_period_s` of message time.
//
// The class only accumulates; deciding when a run ends is the caller's (Evaluation).
// Every event after finish() is ignored, so the metrics are those of the moment the run ended.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "semx/core/byte_io.hpp"
#include "semx/core/states.hpp"

namespace semx::evaluator {

// The message contract's planner states (kUnknown: no PLANNER_STATUS heard yet).
using core::planner_state_from_int;
using core::PlannerState;

// Why a run ended.
enum class Termination {
  kRunning,      // not ended yet
  kPlannerDone,  // the planner declared DONE
  kTimeLimit,    // the evaluator's time limit was reached
  kEpisodeEnd,   // the simulator ended the episode (SIM_EVENT EPISODE_END)
  kStopped,      // the evaluator was stopped (SIGINT/SIGTERM)
  kLogEnd,       // the recorded log ended
};
const char* to_string(Termination t);  // "running", "planner_done", "time_limit", ...

struct CoverageSample {
  double t_s = 0.0;
  double coverage_pct = 0.0;
  double distance_m = 0.0;
  int64_t covered = 0;
  double object_coverage_pct = 0.0;
};

struct MetricsOptions {
  double coverage_threshold = 0.85;  // Time_r: first time coverage >= this fraction
  double high_threshold = 0.95;      // Time_95: the same, for the end of exploration
  double settled_points = 0.5;       // Time_settled: within this many points of the final coverage
  double object_threshold = 0.75;    // Time_o: first time object coverage >= this fraction
  double sample_period_s = 1.0;      // coverage-over-time samples
  double trajectory_step_m = 0.02;   // trajectory points kept for pictures (>= this apart)
};

class RunMetrics {
 public:
  explicit RunMetrics(MetricsOptions options = {});

  const MetricsOptions& options() const { return options_; }

  // Non-finite positions and odometry not newer than the last are ignored.
  void on_odometry(int64_t utime, const Eigen::Vector3d& position);
  // The coverage after a map update stamped `utime` (covered of `target` voxels).
  void on_coverage(int64_t utime, int64_t covered, int64_t target);
  // The object coverage after the same update (covered of `target` object surface voxels).
  void on_object_coverage(int64_t utime, int64_t covered, int64_t target);
  // One COLLISION event; `running_count` is the simulator's count of collisions so far.
  void on_collision(int64_t utime, int64_t running_count);
  // The first DONE fixes the planner's end time; later states are only recorded.
  void on_planner_state(int64_t utime, PlannerState state);
  // Message time moved to `utime`: takes the coverage samples that fell due.
  void advance(int64_t utime);
  // Ends the run at `utime` (see Time_f above); takes a final sample.
  void finish(Termination why, int64_t utime, double time_limit_s = 0.0);

  bool finished() const { return termination_ != Termination::kRunning; }
  Termination termination() const { return termination_; }
  // Latest message time seen (utime).
  int64_t now_utime() const { return now_utime_; }

  // ---- results (valid at any time; final after finish()) ----
  double time_f_s() const;
  double distance_m() const { return distance_m_; }
  double coverage_pct() const;
  int64_t covered() const { return covered_; }
  int64_t target() const { return target_; }
  std::optional<double> time_r_s() const;
  std::optional<double> time_95_s() const;
  // Null before any coverage update; final only after finish().
  std::optional<double> time_settled_s() const;
  // time_f_s() - time_settled_s(), at least 0 (updates stamped after DONE still settle it).
  std::optional<double> end_game_s() const;
  double object_coverage_pct() const;
  std::optional<double> time_o_s() const;
  int64_t collisions() const { return std::max(collision_events_, collision_count_); }
  int64_t collision_events() const { return collision_events_; }
  PlannerState planner_state() const { return planner_state_; }
  std::optional<double> planner_done_s() const;
  std::optional<int64_t> planner_done_utime() const { return done_utime_; }
  const std::vector<CoverageSample>& samples() const { return samples_; }
  const std::vector<Eigen::Vector3d>& trajectory() const { return trajectory_; }
  std::optional<Eigen::Vector3d> position() const;

  // ---- saved state (an evaluator restarted after a crash goes on from it) ----
  // How much of the growing series the saves so far hold.
  struct Saved {
    size_t trajectory = 0, samples = 0, growth = 0;
  };
  // What a save now would leave saved (after a restore: what the restored state holds).
  Saved sizes() const { return {trajectory_.size(), samples_.size(), growth_.size()}; }
  // One journal record: every scalar, and of each series what `saved` does not hold yet (and its
  // last element again, which sample() may have replaced); updates `saved`.
  void save(core::ByteWriter& w, Saved& saved) const;
  // Applies one record of save() on top of this; replaying a journal's records in order rebuilds
  // the saved object. Throws std::runtime_error for a record that does not continue this state.
  void restore(core::ByteReader& r);

 private:
  void sample(int64_t utime);
  void note_time(int64_t utime);

  MetricsOptions options_;
  int64_t now_utime_ = 0;
  bool have_odometry_ = false;
  int64_t last_odometry_utime_ = 0;
  Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();
  double distance_m_ = 0.0;
  std::vector<Eigen::Vector3d> trajectory_;
  int64_t covered_ = 0;
  int64_t target_ = 0;
  std::optional<int64_t> time_r_utime_;
  std::optional<int64_t> time_95_utime_;
  // (utime, covered) at every update that covered more: coverage only grows (a known voxel stays
  // known), so the settling time is found in it once the final value is known.
  std::vector<std::pair<int64_t, int64_t>> growth_;
  int64_t object_covered_ = 0;
  int64_t object_target_ = 0;
  std::optional<int64_t> time_o_utime_;
  int64_t collision_events_ = 0;
  int64_t collision_count_ = 0;
  PlannerState planner_state_ = PlannerState::kUnknown;
  std::optional<int64_t> done_utime_;
  int64_t next_sample_utime_ = 0;
  std::vector<CoverageSample> samples_;
  Termination termination_ = Termination::kRunning;
  int64_t end_utime_ = 0;
  double time_f_s_ = 0.0;
};

}  // namespace semx::evaluator
