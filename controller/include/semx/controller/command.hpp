// What the controller asks of the vehicle (CONTROL_CMD as plain data): hover where it is, or fly
// a world-frame velocity, always with a heading to turn to.
#pragma once

#include <Eigen/Core>

namespace semx::controller {

struct Command {
  enum class Mode { kHold, kVelocity };
  Mode mode = Mode::kHold;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, world frame (kVelocity)
  double yaw = 0.0;                                    // rad, wrapped to (-π, π]: the heading to turn to
  double yaw_rate = 0.0;  // rad/s, the reference's yaw rate (information; the mode is yaw angle)
};

}  // namespace semx::controller
