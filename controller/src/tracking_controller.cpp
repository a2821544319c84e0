#include "semx/controller/tracking_controller.hpp"

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::controller {

Eigen::Vector3d TrackingController::limit(const Eigen::Vector3d& v) const {
  const double n = v.norm();
  if (!std::isfinite(n)) return Eigen::Vector3d::Zero();
  // One scale for both limits keeps the command's direction.
  double s = 1.0;
  if (n > config_.max_command_speed) s = config_.max_command_speed / n;
  const double z = std::abs(v.z()) * s;
  if (z > config_.max_command_speed_z) s *= config_.max_command_speed_z / z;
  return v * s;
}

Command TrackingController::track(const TrajectoryPoint& ref, const VehicleState& vehicle) const {
  Command c;
  c.mode = Command::Mode::kVelocity;
  c.velocity = limit(ref.velocity + config_.accel_feedforward * ref.acceleration +
                     config_.position_gain * (ref.position - vehicle.position) +
                     config_.velocity_gain * (ref.velocity - vehicle.velocity));
  c.yaw = core::wrap_angle(ref.yaw + config_.yaw_feedforward * ref.yaw_rate);
  c.yaw_rate = ref.yaw_rate;
  return c;
}

Command TrackingController::hold_at(const Eigen::Vector3d& position, double yaw,
                                    const VehicleState& vehicle) const {
  Command c;
  c.mode = Command::Mode::kVelocity;
  c.velocity =
      limit(config_.position_gain * (position - vehicle.position) - config_.velocity_gain * vehicle.velocity);
  c.yaw = core::wrap_angle(yaw);
  return c;
}

Command TrackingController::hover(double yaw) {
  Command c;
  c.mode = Command::Mode::kHold;
  c.yaw = core::wrap_angle(yaw);
  return c;
}

}  // namespace semx::controller
