#include "ros_messages.hpp"

namespace semx::rosbridge {

namespace {

std_msgs::Header header(const msg::Header& h) {
  std_msgs::Header r;
  r.stamp = to_ros_time(h.stamp_ns);
  r.frame_id = h.frame_id;
  return r;
}
msg::Header header(const std_msgs::Header& h) { return {from_ros_time(h.stamp), h.frame_id}; }

geometry_msgs::Point point(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}
geometry_msgs::Vector3 vector(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}
template <class P>
Eigen::Vector3d eigen(const P& p) {
  return {p.x, p.y, p.z};
}
geometry_msgs::Quaternion quaternion(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion r;
  r.w = q.w();
  r.x = q.x();
  r.y = q.y();
  r.z = q.z();
  return r;
}
Eigen::Quaterniond quaternion(const geometry_msgs::Quaternion& q) { return {q.w, q.x, q.y, q.z}; }

geometry_msgs::Pose pose(const msg::Pose& p) {
  geometry_msgs::Pose r;
  r.position = point(p.position);
  r.orientation = quaternion(p.orientation);
  return r;
}
msg::Pose pose(const geometry_msgs::Pose& p) { return {eigen(p.position), quaternion(p.orientation)}; }

std_msgs::ColorRGBA color(const msg::Color& c) {
  std_msgs::ColorRGBA r;
  r.r = c.r;
  r.g = c.g;
  r.b = c.b;
  r.a = c.a;
  return r;
}
msg::Color color(const std_msgs::ColorRGBA& c) { return {c.r, c.g, c.b, c.a}; }

}  // namespace

::ros::Time to_ros_time(int64_t ns) {
  ::ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns < 0 ? 0 : ns));
  return t;
}
int64_t from_ros_time(const ::ros::Time& t) { return static_cast<int64_t>(t.toNSec()); }

nav_msgs::Odometry to_ros_msg(const msg::Odometry& m) {
  nav_msgs::Odometry r;
  r.header = header(m.header);
  r.child_frame_id = m.child_frame_id;
  r.pose.pose = pose(m.pose);
  r.twist.twist.linear = vector(m.twist.linear);
  r.twist.twist.angular = vector(m.twist.angular);
  return r;
}
msg::Odometry from_ros_msg(const nav_msgs::Odometry& m) {
  msg::Odometry r;
  r.header = header(m.header);
  r.child_frame_id = m.child_frame_id;
  r.pose = pose(m.pose.pose);
  r.twist.linear = eigen(m.twist.twist.linear);
  r.twist.angular = eigen(m.twist.twist.angular);
  return r;
}

geometry_msgs::TransformStamped to_ros_msg(const msg::TransformStamped& m) {
  geometry_msgs::TransformStamped r;
  r.header = header(m.header);
  r.child_frame_id = m.child_frame_id;
  r.transform.translation = vector(m.translation);
  r.transform.rotation = quaternion(m.rotation);
  return r;
}
msg::TransformStamped from_ros_msg(const geometry_msgs::TransformStamped& m) {
  msg::TransformStamped r;
  r.header = header(m.header);
  r.child_frame_id = m.child_frame_id;
  r.translation = eigen(m.transform.translation);
  r.rotation = quaternion(m.transform.rotation);
  return r;
}

geometry_msgs::PoseStamped to_ros_msg(const msg::PoseStamped& m) {
  geometry_msgs::PoseStamped r;
  r.header = header(m.header);
  r.pose = pose(m.pose);
  return r;
}
msg::PoseStamped from_ros_msg(const geometry_msgs::PoseStamped& m) { return {header(m.header), pose(m.pose)}; }

geometry_msgs::TwistStamped to_ros_msg(const msg::TwistStamped& m) {
  geometry_msgs::TwistStamped r;
  r.header = header(m.header);
  r.twist.linear = vector(m.twist.linear);
  r.twist.angular = vector(m.twist.angular);
  return r;
}
msg::TwistStamped from_ros_msg(const geometry_msgs::TwistStamped& m) {
  msg::TwistStamped r;
  r.header = header(m.header);
  r.twist.linear = eigen(m.twist.linear);
  r.twist.angular = eigen(m.twist.angular);
  return r;
}

nav_msgs::Path to_ros_msg(const msg::Path& m) {
  nav_msgs::Path r;
  r.header = header(m.header);
  r.poses.reserve(m.poses.size());
  for (const auto& p : m.poses) r.poses.push_back(to_ros_msg(p));
  return r;
}
msg::Path from_ros_msg(const nav_msgs::Path& m) {
  msg::Path r;
  r.header = header(m.header);
  for (const auto& p : m.poses) r.poses.push_back(from_ros_msg(p));
  return r;
}

sensor_msgs::PointCloud2 to_ros_msg(const msg::PointCloud2& m) {
  sensor_msgs::PointCloud2 r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  for (const auto& f : m.fields) {
    sensor_msgs::PointField p;
    p.name = f.name;
    p.offset = f.offset;
    p.datatype = f.datatype;
    p.count = f.count;
    r.fields.push_back(p);
  }
  r.is_bigendian = m.is_bigendian;
  r.point_step = m.point_step;
  r.row_step = m.row_step;
  r.data = m.data;
  r.is_dense = m.is_dense;
  return r;
}
msg::PointCloud2 from_ros_msg(const sensor_msgs::PointCloud2& m) {
  msg::PointCloud2 r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  for (const auto& f : m.fields) r.fields.push_back({f.name, f.offset, f.datatype, f.count});
  r.is_bigendian = m.is_bigendian;
  r.point_step = m.point_step;
  r.row_step = m.row_step;
  r.data = m.data;
  r.is_dense = m.is_dense;
  return r;
}

sensor_msgs::Image to_ros_msg(const msg::Image& m) {
  sensor_msgs::Image r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  r.encoding = m.encoding;
  r.is_bigendian = m.is_bigendian;
  r.step = m.step;
  r.data = m.data;
  return r;
}
msg::Image from_ros_msg(const sensor_msgs::Image& m) {
  msg::Image r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  r.encoding = m.encoding;
  r.is_bigendian = m.is_bigendian;
  r.step = m.step;
  r.data = m.data;
  return r;
}

sensor_msgs::CameraInfo to_ros_msg(const msg::CameraInfo& m) {
  sensor_msgs::CameraInfo r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  r.distortion_model = m.distortion_model;
  r.D = m.D;
  for (int i = 0; i < 9; ++i) r.K[i] = m.K[i];
  for (int i = 0; i < 9; ++i) r.R[i] = m.R[i];
  for (int i = 0; i < 12; ++i) r.P[i] = m.P[i];
  return r;
}
msg::CameraInfo from_ros_msg(const sensor_msgs::CameraInfo& m) {
  msg::CameraInfo r;
  r.header = header(m.header);
  r.height = m.height;
  r.width = m.width;
  r.distortion_model = m.distortion_model;
  r.D = m.D;
  for (int i = 0; i < 9; ++i) r.K[i] = m.K[i];
  for (int i = 0; i < 9; ++i) r.R[i] = m.R[i];
  for (int i = 0; i < 12; ++i) r.P[i] = m.P[i];
  return r;
}

visualization_msgs::MarkerArray to_ros_msg(const msg::MarkerArray& a) {
  visualization_msgs::MarkerArray r;
  r.markers.reserve(a.markers.size());
  for (const auto& m : a.markers) {
    visualization_msgs::Marker k;
    k.header = header(m.header);
    k.ns = m.ns;
    k.id = m.id;
    k.type = m.type;
    k.action = m.action;
    k.pose = pose(m.pose);
    k.scale = vector(m.scale);
    k.color = color(m.color);
    k.lifetime.fromNSec(m.lifetime_ns);
    k.frame_locked = m.frame_locked;
    k.points.reserve(m.points.size());
    for (const auto& p : m.points) k.points.push_back(point(p));
    for (const auto& c : m.colors) k.colors.push_back(color(c));
    k.text = m.text;
    r.markers.push_back(std::move(k));
  }
  return r;
}
msg::MarkerArray from_ros_msg(const visualization_msgs::MarkerArray& a) {
  msg::MarkerArray r;
  for (const auto& k : a.markers) {
    msg::Marker m;
    m.header = header(k.header);
    m.ns = k.ns;
    m.id = k.id;
    m.type = k.type;
    m.action = k.action;
    m.pose = pose(k.pose);
    m.scale = eigen(k.scale);
    m.color = color(k.color);
    m.lifetime_ns = static_cast<int64_t>(k.lifetime.toNSec());
    m.frame_locked = k.frame_locked;
    for (const auto& p : k.points) m.points.push_back(eigen(p));
    for (const auto& c : k.colors) m.colors.push_back(color(c));
    m.text = k.text;
    r.markers.push_back(std::move(m));
  }
  return r;
}

diagnostic_msgs::DiagnosticArray to_ros_msg(const msg::DiagnosticArray& a) {
  diagnostic_msgs::DiagnosticArray r;
  r.header = header(a.header);
  for (const auto& s : a.status) {
    diagnostic_msgs::DiagnosticStatus d;
    d.level = s.level;
    d.name = s.name;
    d.message = s.message;
    d.hardware_id = s.hardware_id;
    for (const auto& kv : s.values) {
      diagnostic_msgs::KeyValue k;
      k.key = kv.key;
      k.value = kv.value;
      d.values.push_back(k);
    }
    r.status.push_back(std::move(d));
  }
  return r;
}
msg::DiagnosticArray from_ros_msg(const diagnostic_msgs::DiagnosticArray& a) {
  msg::DiagnosticArray r;
  r.header = header(a.header);
  for (const auto& d : a.status) {
    msg::DiagnosticStatus s;
    s.level = static_cast<int8_t>(d.level);
    s.name = d.name;
    s.message = d.message;
    s.hardware_id = d.hardware_id;
    for (const auto& kv : d.values) s.values.push_back({kv.key, kv.value});
    r.status.push_back(std::move(s));
  }
  return r;
}

}  // namespace semx::rosbridge
