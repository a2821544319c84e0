// Where an exploration's time goes (issue 30): the run is cut into slices of `slice_s` of message
// time, and each slice up to Time_f is put in one of five uses:
//
//   new       flying (mean speed >= move_speed) while the map grows by >= new_rate of target
//             volume per second: the camera brings in new space;
//   revisit   flying while the map grows by less: the vehicle crosses space it has mapped
//             (backtracking between rooms, transits to a far goal);
//   turn      not flying, turning at >= turn_rate (a turn in place);
//   hover     neither (dwell at a goal, waiting for a plan, braking);
//   end game  every slice that starts at or after Time_settled (the map stopped growing; the
//             evaluator's end game, run_metrics.hpp), whatever the vehicle did.
//
// The evaluator feeds it from ODOMETRY and the coverage of its ground truth (time_split.json and
// time_split.png in the run folder); semx-perf-planner from its closed loop. Why these cuts: the
// end game is issue 33's measure already, and "revisit" is flight the map does not pay for, which
// is what a room order or a global tour should remove; a flying slice that sees new space is
// exploration however it got there.
//
// Feeding: poses and coverage in non-decreasing time, in any interleaving; a slice's growth is
// the covered count at its end minus that at its start (the latest count fed before each).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace semx::core {

enum class TimeUse : uint8_t { kNew = 0, kRevisit = 1, kTurn = 2, kHover = 3, kEndGame = 4 };
inline constexpr int kTimeUses = 5;
const char* to_string(TimeUse u);  // "new", "revisit", "turn", "hover", "end_game"
// time_split.json's "slices": one letter per slice, the use's in TimeUse order, so the run's
// sequence reads at a glance and stays small (the bench report reads it back).
inline constexpr char kTimeUseLetters[kTimeUses + 1] = "nrthe";

struct TimeSplitOptions {
  double slice_s = 0.5;      // s
  double move_speed = 0.2;   // m/s: a slice flying at least this on the mean is flight
  double turn_rate = 0.15;   // rad/s: a slice not flying that turns at least this is a turn
  double new_rate = 0.25;    // m³/s of target volume newly known: flight that sees new space
  // Revisited by place: flight within place_radius of where the vehicle was place_age_s or more
  // earlier (a second measure, independent of the map: backtracking over the same ground).
  double place_radius = 1.0;  // m
  double place_age_s = 10.0;  // s
};

struct TimeSlice {
  double t0 = 0.0, t1 = 0.0;
  TimeUse use = TimeUse::kHover;
  double distance = 0.0;  // m flown in the slice
  double turn = 0.0;      // rad turned (sum of |yaw changes|)
  double new_m3 = 0.0;    // target volume the map gained
  // The poses in it (the first is the slice's start when known), for pictures.
  std::vector<Eigen::Vector3d> points;
};

struct TimeSplitResult {
  TimeSplitOptions options;
  double time_f = 0.0;
  double time_settled = 0.0;
  std::array<double, kTimeUses> time_s{};      // s per use
  std::array<double, kTimeUses> distance_m{};  // m flown per use
  std::array<double, kTimeUses> new_m3{};      // volume gained per use
  double revisit_by_place_m = 0.0;             // m flown over ground covered before (options)
  double distance_total_m = 0.0;
  std::vector<TimeSlice> slices;

  double share(TimeUse u) const;  // of time_f (0 when time_f is 0)
  // time_split.json: options, per-use seconds, share, metres and volume, the slices' uses.
  std::string to_json() const;
};

class TimeSplit {
 public:
  explicit TimeSplit(TimeSplitOptions options = {});

  // The vehicle's pose at t (s). Non-finite poses and times before the last are ignored; a yaw
  // that is not finite counts no turn.
  void on_pose(double t, const Eigen::Vector3d& position, double yaw);
  // The map's covered target voxels after an update stamped t.
  void on_covered(double t, int64_t covered);
  // Slices up to time_f, the end game from time_settled on; a covered voxel is `voxel_volume` m³.
  TimeSplitResult finish(double time_f, double time_settled, double voxel_volume) const;

  const TimeSplitOptions& options() const { return options_; }

 private:
  struct Pose {
    double t;
    Eigen::Vector3d p;
    double yaw;
  };
  TimeSplitOptions options_;
  std::vector<Pose> poses_;
  std::vector<std::pair<double, int64_t>> covered_;  // (t, covered) at each change
};

}  // namespace semx::core
