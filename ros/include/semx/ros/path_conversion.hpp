// The planner's path and the controller's trajectory as nav_msgs/Path in the map frame: every
// waypoint a pose with its heading as a rotation about z; the trajectory sampled every dt
// seconds of its B-spline, each pose stamped with its time along it.
#pragma once

#include <vector>

#include "semx/controller/path.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

msg::Path to_ros(const controller::Path& p, const std::string& frame, const TimeBase& time);
// Waypoints and yaws back (plan id and speed are not carried); false when a pose is not finite.
bool path_from_ros(const msg::Path& m, controller::Path& out);

msg::Path to_ros(const controller::Trajectory& t, double dt, const std::string& frame, const TimeBase& time);

struct TimedPose {
  int64_t utime = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};
bool trajectory_from_ros(const msg::Path& m, const TimeBase& time, std::vector<TimedPose>& out);

// Heading <-> a rotation about z (the pose's roll and pitch are ignored when read).
Eigen::Quaterniond yaw_quaternion(double yaw);
double quaternion_yaw(const Eigen::Quaterniond& q);

}  // namespace semx::rosbridge
