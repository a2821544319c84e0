// semx's commands for a vehicle flown by ROS (MAVROS offboard, or any velocity interface):
// geometry_msgs/TwistStamped (world-frame velocity, yaw rate as angular.z: MAVROS's
// setpoint_velocity/cmd_vel, in ENU; MAVROS converts to NED itself) and geometry_msgs/PoseStamped
// (MAVROS's setpoint_position/local: a point of the trajectory a little ahead).
//
// semx's controller sends a velocity with a heading to turn to; a twist carries a yaw rate, so
// the heading becomes a rate: gain times the heading error, limited (SetpointConfig). HOLD sends
// zero velocity; ACCELERATION (no semx controller sends it) is held as zero velocity too.
#pragma once

#include <optional>

#include "semx/controller/trajectory.hpp"
#include "semx/ros/bridge_values.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

struct SetpointConfig {
  double yaw_gain = 1.5;      // 1/s: yaw rate per radian of heading error
  double max_yaw_rate = 1.0;  // rad/s
  double lead_s = 0.3;        // position setpoints: this far ahead on the trajectory
};

// `vehicle_yaw`: the vehicle's current heading (for a YAW_ANGLE command); nullopt: none known,
// the heading is then not turned (angular.z = 0).
msg::TwistStamped velocity_setpoint(const VehicleCommand& c, std::optional<double> vehicle_yaw,
                                    const SetpointConfig& config, const std::string& frame, const TimeBase& time);
// A twist back as a command: VELOCITY with YAW_RATE.
VehicleCommand command_from_ros(const msg::TwistStamped& m, const TimeBase& time);

// The trajectory's point lead_s after `utime` (its end once past it), with its heading.
msg::PoseStamped position_setpoint(const controller::Trajectory& t, int64_t utime, const SetpointConfig& config,
                                   const std::string& frame, const TimeBase& time);

}  // namespace semx::rosbridge
