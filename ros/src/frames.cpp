#include "semx/ros/frames.hpp"

#include <cmath>

#include "semx/runtime/pinhole_camera.hpp"

namespace semx::rosbridge {

Eigen::Isometry3d optical_in_camera_link() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // The same fixed rotation as the one between semx's body and a forward-looking optical frame.
  T.linear() = runtime::optical_in_body();
  return T;
}

Eigen::Isometry3d camera_link_in_body(const Eigen::Isometry3d& T_world_body,
                                      const Eigen::Isometry3d& T_world_optical) {
  return T_world_body.inverse() * T_world_optical * optical_in_camera_link().inverse();
}

bool TimeBase::adopt(int64_t ros_ns) {
  if (fixed_) return true;
  if (ros_ns <= 0) return false;
  origin_ns_ = (ros_ns / 1000000000) * 1000000000;
  fixed_ = true;
  return true;
}

bool TimeBase::to_utime(int64_t ros_ns, int64_t& utime) const {
  const int64_t d = ros_ns - origin_ns_;
  if (d < 0) return false;
  utime = (d + 500) / 1000;
  return true;
}

}  // namespace semx::rosbridge
