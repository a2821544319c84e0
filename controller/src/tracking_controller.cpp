#include "semx/controller/tracking_controller.hpp"

#include "semx/controller/angles.hpp"

namespace semx::controller {

Eigen::Vector3d TrackingController::limit(const Eigen::Vector3d& v) const {
  const double n = v.norm();
  if (!std::isfinite(n)) return Eigen::Vector3d::Zero();
  return n > config_.max_command_speed ? Eigen::Vector3d(v * (config_.max_command_speed / n)) : v;
}

Command TrackingController::track(const TrajectoryPoint& ref, const VehicleState& vehicle) const {
  Command c;
  c.mode = Command::Mode::kVelocity;
  c.velocity = limit(ref.velocity + config_.accel_feedforward * ref.acceleration +
                     config_.position_gain * (ref.position - vehicle.position) +
                     config_.velocity_gain * (ref.velocity - vehicle.velocity));
  c.yaw = wrap_angle(ref.yaw + config_.yaw_feedforward * ref.yaw_rate);
  c.yaw_rate = ref.yaw_rate;
  return c;
}

Command TrackingController::hold_at(const Eigen::Vector3d& position, double yaw,
                                    const VehicleState& vehicle) const {
  Command c;
  c.mode = Command::Mode::kVelocity;
  c.velocity =
      limit(config_.position_gain * (position - vehicle.position) - config_.velocity_gain * vehicle.velocity);
  c.yaw = wrap_angle(yaw);
  return c;
}

Command TrackingController::hover(double yaw) {
  Command c;
  c.mode = Command::Mode::kHold;
  c.yaw = wrap_angle(yaw);
  return c;
}

}  // namespace semx::controller
