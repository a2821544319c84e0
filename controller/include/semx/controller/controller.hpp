// The controller: paths in, commands out, on message time only.
//
// Inputs are handed in as they arrive (on_path, on_esdf, on_odometry); step(utime) runs one
// control cycle at that simulation time and is the only place decisions are made, so a log
// replays identically. Each step, in order:
//   1. inputs: odometry older than safety.max_odometry_age or an ESDF older than
//      safety.max_esdf_age (or none yet) → STALE_INPUT: drop the trajectory, hover;
//   2. the newest pending path: rejected if bad (path.hpp), older than path.max_age or starting
//      farther than path.max_start_offset from the vehicle (REJECTED, hover); else a trajectory
//      is generated (trajectory_generator.hpp) from the vehicle's state; none safe → REJECTED;
//   3. a new ESDF since the last step: the next safety.check_horizon seconds of the trajectory
//      are checked (flight rule); a predicted collision → BRAKING: drop it, hover;
//   4. the command: track the trajectory (TRACKING), hold its end once done (HOLDING), or hover.
// A stopped controller (BRAKING, REJECTED, STALE_INPUT, IDLE) stays so until the next path.
#pragma once

#include <memory>
#include <optional>

#include "semx/controller/command.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/controller_status.hpp"
#include "semx/controller/distance_field.hpp"
#include "semx/controller/path.hpp"
#include "semx/controller/tracking_controller.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/controller/trajectory_generator.hpp"
#include "semx/controller/vehicle_state.hpp"

namespace semx::controller {

struct StepOutput {
  Command command;
  ControllerStatus status;
  bool status_changed = false;                 // state, plan or reason differ from the last step
  const Trajectory* new_trajectory = nullptr;  // the trajectory started at this step, if any
};

class Controller {
 public:
  explicit Controller(const ControllerConfig& config);

  void on_path(Path path);
  void on_esdf(std::shared_ptr<const DistanceField> field, int64_t utime);
  void on_odometry(const VehicleState& state);
  StepOutput step(int64_t utime);
  // Forget everything (a new episode: the clock restarted).
  void reset();

  const ControllerStatus& status() const { return status_; }
  const ControllerCounters& counters() const { return counters_; }
  const Trajectory* trajectory() const { return trajectory_ ? &*trajectory_ : nullptr; }
  const GenerationResult& last_generation() const { return last_generation_; }
  const ControllerConfig& config() const { return config_; }
  const TrajectoryGenerator& generator() const { return generator_; }

 private:
  std::string stale_reason(int64_t now) const;
  void process_path(int64_t now, StepOutput& out);
  void reject(const Path& path, const std::string& why, bool unsafe);
  void stop(ControllerState state, const std::string& reason);
  double hover_yaw() const { return odometry_ ? odometry_->yaw : 0.0; }

  ControllerConfig config_;
  TrajectoryGenerator generator_;
  TrackingController tracker_;

  std::optional<Path> pending_;
  std::optional<VehicleState> odometry_;
  std::shared_ptr<const DistanceField> esdf_;
  int64_t esdf_utime_ = 0;
  bool esdf_new_ = false;

  std::optional<Trajectory> trajectory_;
  double error_sq_sum_ = 0.0;
  int64_t error_count_ = 0;
  GenerationResult last_generation_;
  ControllerStatus status_;
  ControllerCounters counters_;
};

}  // namespace semx::controller
