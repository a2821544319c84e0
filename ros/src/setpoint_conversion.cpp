#include "semx/ros/setpoint_conversion.hpp"

#include <algorithm>
#include <cmath>

#include "semx/core/angles.hpp"
#include "semx/ros/path_conversion.hpp"

namespace semx::rosbridge {

msg::TwistStamped velocity_setpoint(const VehicleCommand& c, std::optional<double> vehicle_yaw,
                                    const SetpointConfig& config, const std::string& frame, const TimeBase& time) {
  msg::TwistStamped m;
  m.header.stamp_ns = time.to_ros_ns(c.utime);
  m.header.frame_id = frame;
  if (c.mode == VehicleCommand::Mode::kVelocity) m.twist.linear = c.setpoint;
  double rate = 0.0;
  if (c.yaw_mode == VehicleCommand::YawMode::kRate) {
    rate = c.yaw_rate;
  } else if (vehicle_yaw) {
    rate = config.yaw_gain * core::wrap_angle(c.yaw - *vehicle_yaw);
  }
  m.twist.angular.z() = std::clamp(rate, -config.max_yaw_rate, config.max_yaw_rate);
  return m;
}

VehicleCommand command_from_ros(const msg::TwistStamped& m, const TimeBase& time) {
  VehicleCommand c;
  time.to_utime(m.header.stamp_ns, c.utime);
  c.mode = VehicleCommand::Mode::kVelocity;
  c.setpoint = m.twist.linear;
  c.yaw_mode = VehicleCommand::YawMode::kRate;
  c.yaw_rate = m.twist.angular.z();
  return c;
}

msg::PoseStamped position_setpoint(const controller::Trajectory& t, int64_t utime, const SetpointConfig& config,
                                   const std::string& frame, const TimeBase& time) {
  msg::PoseStamped m;
  m.header.stamp_ns = time.to_ros_ns(utime);
  m.header.frame_id = frame;
  if (t.empty()) return m;
  const double s = std::clamp(t.time_at(utime) + config.lead_s, 0.0, t.duration());
  const controller::TrajectoryPoint p = t.sample(s);
  m.pose.position = p.position;
  m.pose.orientation = yaw_quaternion(core::wrap_angle(p.yaw));
  return m;
}

}  // namespace semx::rosbridge
