#include "semx/ros/path_conversion.hpp"

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::rosbridge {

Eigen::Quaterniond yaw_quaternion(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

double quaternion_yaw(const Eigen::Quaterniond& q) { return core::yaw_of_quaternion(q.w(), q.x(), q.y(), q.z()); }

msg::Path to_ros(const controller::Path& p, const std::string& frame, const TimeBase& time) {
  msg::Path m;
  m.header.stamp_ns = time.to_ros_ns(p.utime);
  m.header.frame_id = frame;
  for (std::size_t i = 0; i < p.waypoints.size(); ++i) {
    msg::PoseStamped ps;
    ps.header = m.header;
    ps.pose.position = p.waypoints[i];
    ps.pose.orientation = yaw_quaternion(i < p.yaws.size() ? p.yaws[i] : 0.0);
    m.poses.push_back(std::move(ps));
  }
  return m;
}

bool path_from_ros(const msg::Path& m, controller::Path& out) {
  controller::Path p;
  for (const auto& ps : m.poses) {
    if (!ps.pose.position.allFinite() || !ps.pose.orientation.coeffs().allFinite()) return false;
    p.waypoints.push_back(ps.pose.position);
    p.yaws.push_back(quaternion_yaw(ps.pose.orientation));
  }
  out = std::move(p);
  return true;
}

msg::Path to_ros(const controller::Trajectory& t, double dt, const std::string& frame, const TimeBase& time) {
  msg::Path m;
  m.header.stamp_ns = time.to_ros_ns(t.start_utime);
  m.header.frame_id = frame;
  if (t.empty() || !(dt > 0)) return m;
  const double duration = t.duration();
  const int n = static_cast<int>(std::ceil(duration / dt - 1e-9));
  for (int i = 0; i <= n; ++i) {
    const double s = std::min(duration, i * dt);
    const controller::TrajectoryPoint p = t.sample(s);
    msg::PoseStamped ps;
    ps.header.frame_id = frame;
    ps.header.stamp_ns = time.to_ros_ns(t.start_utime + static_cast<int64_t>(std::llround(s * 1e6)));
    ps.pose.position = p.position;
    ps.pose.orientation = yaw_quaternion(core::wrap_angle(p.yaw));
    m.poses.push_back(std::move(ps));
  }
  return m;
}

bool trajectory_from_ros(const msg::Path& m, const TimeBase& time, std::vector<TimedPose>& out) {
  std::vector<TimedPose> poses;
  for (const auto& ps : m.poses) {
    TimedPose p;
    if (!time.to_utime(ps.header.stamp_ns, p.utime)) return false;
    if (!ps.pose.position.allFinite() || !ps.pose.orientation.coeffs().allFinite()) return false;
    p.position = ps.pose.position;
    p.yaw = quaternion_yaw(ps.pose.orientation);
    poses.push_back(p);
  }
  out = std::move(poses);
  return true;
}

}  // namespace semx::rosbridge
