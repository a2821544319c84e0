// The vehicle's state: semx odometry <-> nav_msgs/Odometry and the map -> base_link transform;
// geometry_msgs/PoseStamped (e.g. /mavros/local_position/pose) -> semx odometry.
//
// nav_msgs/Odometry carries the pose in header.frame_id and the twist in child_frame_id (the
// body), where semx's odometry carries a world-frame velocity: the linear part is rotated, the
// angular part (body rates) is the same in both.
#pragma once

#include <string>

#include "semx/ros/bridge_values.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

msg::Odometry to_ros(const VehicleOdometry& o, const FrameNames& frames, const TimeBase& time);
msg::TransformStamped body_transform(const VehicleOdometry& o, const FrameNames& frames, const TimeBase& time);

// "" when usable, else why not: a stamp before the time origin, values not finite, an
// orientation that is not a unit quaternion (within 1e-3; it is normalised).
std::string from_ros(const msg::Odometry& m, const TimeBase& time, VehicleOdometry& out);

// A pose stream made into odometry: the velocity is the difference to the previous pose (world
// frame), the body rates that of the orientation; zero for the first pose and after a gap of
// more than max_gap_s or a stamp that does not advance.
class PoseDifferentiator {
 public:
  explicit PoseDifferentiator(double max_gap_s = 0.5) : max_gap_s_(max_gap_s) {}
  std::string convert(const msg::PoseStamped& m, const TimeBase& time, VehicleOdometry& out);

 private:
  double max_gap_s_;
  bool has_previous_ = false;
  VehicleOdometry previous_;
};

}  // namespace semx::rosbridge
