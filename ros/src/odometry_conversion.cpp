#include "semx/ros/odometry_conversion.hpp"

#include <cmath>

namespace semx::rosbridge {

namespace {

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// "" for a usable orientation (normalised in place).
std::string check_orientation(Eigen::Quaterniond& q) {
  if (!q.coeffs().allFinite()) return "orientation not finite";
  if (std::abs(q.norm() - 1.0) > 1e-3) return "orientation not a unit quaternion";
  q.normalize();
  return "";
}

}  // namespace

msg::Odometry to_ros(const VehicleOdometry& o, const FrameNames& frames, const TimeBase& time) {
  msg::Odometry m;
  m.header.stamp_ns = time.to_ros_ns(o.utime);
  m.header.frame_id = frames.map;
  m.child_frame_id = frames.body;
  m.pose.position = o.position;
  m.pose.orientation = o.orientation;
  m.twist.linear = o.orientation.conjugate() * o.velocity;
  m.twist.angular = o.angular_velocity;
  return m;
}

msg::TransformStamped body_transform(const VehicleOdometry& o, const FrameNames& frames, const TimeBase& time) {
  msg::TransformStamped t;
  t.header.stamp_ns = time.to_ros_ns(o.utime);
  t.header.frame_id = frames.map;
  t.child_frame_id = frames.body;
  t.translation = o.position;
  t.rotation = o.orientation;
  return t;
}

std::string from_ros(const msg::Odometry& m, const TimeBase& time, VehicleOdometry& out) {
  VehicleOdometry o;
  if (!time.to_utime(m.header.stamp_ns, o.utime)) return "stamp before the time origin";
  o.position = m.pose.position;
  o.orientation = m.pose.orientation;
  if (!finite(o.position) || !finite(m.twist.linear) || !finite(m.twist.angular)) return "values not finite";
  if (std::string why = check_orientation(o.orientation); !why.empty()) return why;
  o.velocity = o.orientation * m.twist.linear;
  o.angular_velocity = m.twist.angular;
  out = o;
  return "";
}

std::string PoseDifferentiator::convert(const msg::PoseStamped& m, const TimeBase& time, VehicleOdometry& out) {
  VehicleOdometry o;
  if (!time.to_utime(m.header.stamp_ns, o.utime)) return "stamp before the time origin";
  o.position = m.pose.position;
  o.orientation = m.pose.orientation;
  if (!finite(o.position)) return "values not finite";
  if (std::string why = check_orientation(o.orientation); !why.empty()) return why;
  const double dt = has_previous_ ? 1e-6 * static_cast<double>(o.utime - previous_.utime) : 0.0;
  if (dt > 0.0 && dt <= max_gap_s_) {
    o.velocity = (o.position - previous_.position) / dt;
    // Body rates: the rotation from the previous orientation to this one, in the body frame.
    const Eigen::AngleAxisd delta(previous_.orientation.conjugate() * o.orientation);
    o.angular_velocity = delta.axis() * (delta.angle() / dt);
    if (!o.angular_velocity.allFinite()) o.angular_velocity.setZero();
  }
  if (!has_previous_ || o.utime > previous_.utime) {
    previous_ = o;
    has_previous_ = true;
  }
  out = o;
  return "";
}

}  // namespace semx::rosbridge
