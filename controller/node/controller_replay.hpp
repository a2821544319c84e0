// Generating a logged run's paths again, offline (semx-controller-replay): for each PLAN_PATH of
// an LCM log, the trajectory the controller would make of it now, from the newest ODOMETRY and
// ESDF_LOCAL logged before it and a given configuration. It answers why a run flew a path on the
// fallback, and what a configuration change does on the paths a run really sent, without flying
// the run again. The log must hold ESDF_LOCAL (./semx demo --full-log, or --arg
// "log_channels=CAMERA_.*" to leave out only the camera).
//
// The controller takes a path at its next tick, with the odometry of that tick; the replay uses
// the odometry logged before the path, a few milliseconds older. The results therefore match the
// run's CONTROLLER_STATUS reasons closely but not always to the digit.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "semx/controller/controller_config.hpp"
#include "semx/controller/trajectory_generator.hpp"

namespace semx::controller {

class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ReplayedPath {
  double time = 0.0;  // s of message time (the path's utime)
  int64_t plan_id = 0;
  std::size_t waypoints = 0;
  GenerationResult generation;
};

struct PathReplay {
  std::vector<ReplayedPath> paths;  // those within [from, to), in the log's order
  int skipped = 0;                  // no ESDF or odometry yet, or the start too far from the vehicle
  int malformed = 0;                // events on the three channels that do not decode or pass the checks
  int esdf_events = 0;
  std::string session;  // the log session's summary of what was left out ("" when nothing)
};

// Throws ReplayError naming the file when it is missing or not a readable LCM log.
PathReplay replay_paths(const std::string& log_path, const ControllerConfig& config, double from = -1e300,
                        double to = 1e300);

}  // namespace semx::controller
