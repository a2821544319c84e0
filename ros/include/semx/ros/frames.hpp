// The ROS frames and clock of the bridge (REP 103 and REP 105).
//
// semx's world is ENU-like (x, y horizontal, z up) and is published as `map`; the body frame
// (x forward, y left, z up) is `base_link`; `camera_link` is the camera's body-like frame and
// `camera_optical_frame` the optical frame semx's camera model uses (z forward, x right, y down),
// which every image's header names. Durations and positions are SI throughout (m, s, rad).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>

namespace semx::rosbridge {

struct FrameNames {
  std::string map = "map";
  std::string body = "base_link";
  std::string camera = "camera_link";
  std::string optical = "camera_optical_frame";
};

// camera_link <- optical: REP 103's fixed rotation between a camera's body-like frame and its
// optical frame (optical z = link x, optical x = -link y, optical y = -link z).
Eigen::Isometry3d optical_in_camera_link();

// base_link <- camera_link, from the body's and the optical frame's world poses at one instant.
Eigen::Isometry3d camera_link_in_body(const Eigen::Isometry3d& T_world_body,
                                      const Eigen::Isometry3d& T_world_optical);

// semx message time (µs) <-> ROS time (ns). ROS time = utime + origin. Out of a simulated set the
// origin is 0: ROS runs on the simulator's time through /clock (use_sim_time). Into an external
// set the origin is the first ROS time seen, floored to a whole second, so semx's time starts
// near 0 as it does in the simulator (a sim-time bag keeps origin 0); earlier stamps are refused.
class TimeBase {
 public:
  TimeBase() = default;
  explicit TimeBase(int64_t origin_ns) : origin_ns_(origin_ns), fixed_(true) {}

  // Adopts the origin from the first nonzero ROS time (a no-op once fixed); returns whether
  // the origin is known.
  bool adopt(int64_t ros_ns);
  bool known() const { return fixed_; }
  int64_t origin_ns() const { return origin_ns_; }

  int64_t to_ros_ns(int64_t utime) const { return utime * 1000 + origin_ns_; }
  // Rounds to the nearest microsecond; false for times before the origin.
  bool to_utime(int64_t ros_ns, int64_t& utime) const;

 private:
  int64_t origin_ns_ = 0;
  bool fixed_ = false;
};

}  // namespace semx::rosbridge
