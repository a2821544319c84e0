// The controller process around the logic: LCM subscriptions in, the control cycle on each
// SIM_CLOCK tick, messages out (docs/controller.md lists the channels).
//
//   subscribes  PLAN_PATH (path_t), ESDF_LOCAL (esdf_local_t), ODOMETRY (odometry_t)
//   publishes   CONTROL_CMD every control step, TRAJECTORY when a trajectory starts,
//               CONTROLLER_STATUS at status_rate_hz and on every change (message time)
#pragma once

#include <cstdint>

#include "semx/controller/controller.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/runtime/node.hpp"

namespace semx::controller {

class ControllerNode {
 public:
  ControllerNode(runtime::NodeOptions options, const ControllerConfig& config);

  runtime::Node& node() { return node_; }
  const runtime::Node& node() const { return node_; }
  Controller& controller() { return controller_; }
  // Runs until shutdown, then prints the counters (how many trajectories took the fallback and
  // why) to stdout: RUN/logs/controller.log.
  int run();

  // One tick of simulation time (what SIM_CLOCK triggers); public for tests.
  void on_tick(int64_t tick, int64_t utime);

 private:
  void publish_status(const ControllerStatus& s, int64_t utime);
  void update_node_state();
  int64_t step_period_us() const;  // of rate_hz, in message time

  ControllerConfig config_;
  runtime::Node node_;
  Controller controller_;
  int64_t last_step_utime_ = -1;
  int64_t last_status_utime_ = -1;
};

}  // namespace semx::controller
