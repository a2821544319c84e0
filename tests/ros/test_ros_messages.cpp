// The node's copy between the plain structs and the real ROS 1 messages: every message type the
// bridge sends or reads goes plain -> ROS -> serialised bytes -> ROS -> plain and comes back equal.
#include <gtest/gtest.h>
#include <ros/serialization.h>

#include "ros_messages.hpp"
#include "semx/ros/camera_conversion.hpp"
#include "semx/ros/cloud_conversion.hpp"
#include "semx/ros/marker_conversion.hpp"
#include "semx/ros/odometry_conversion.hpp"
#include "semx/ros/path_conversion.hpp"
#include "semx/ros/setpoint_conversion.hpp"
#include "semx/ros/status_conversion.hpp"

using namespace semx;
using namespace semx::rosbridge;

namespace {

// Through roscpp's wire format and back.
template <class R>
R wire(const R& m) {
  const uint32_t n = ::ros::serialization::serializationLength(m);
  std::vector<uint8_t> buffer(n);
  ::ros::serialization::OStream out(buffer.data(), n);
  ::ros::serialization::serialize(out, m);
  R back;
  ::ros::serialization::IStream in(buffer.data(), n);
  ::ros::serialization::deserialize(in, back);
  return back;
}

template <class M>
M round_trip(const M& m) {
  return from_ros_msg(wire(to_ros_msg(m)));
}

void same_header(const msg::Header& a, const msg::Header& b) {
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.frame_id, b.frame_id);
}

}  // namespace

TEST(RosMessages, OdometryTransformPoseTwist) {
  msg::Odometry o;
  o.header = {1234567891011, "map"};
  o.child_frame_id = "base_link";
  o.pose.position = {1.25, -3.5, 0.75};
  o.pose.orientation = Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5);
  o.twist.linear = {0.1, 0.2, 0.3};
  o.twist.angular = {-0.4, 0.5, -0.6};
  const msg::Odometry b = round_trip(o);
  same_header(b.header, o.header);
  EXPECT_EQ(b.child_frame_id, o.child_frame_id);
  EXPECT_EQ(b.pose.position, o.pose.position);
  EXPECT_EQ(b.pose.orientation.coeffs(), o.pose.orientation.coeffs());
  EXPECT_EQ(b.twist.linear, o.twist.linear);
  EXPECT_EQ(b.twist.angular, o.twist.angular);

  msg::TransformStamped t;
  t.header = {42, "base_link"};
  t.child_frame_id = "camera_link";
  t.translation = {0.1, 0, 0.05};
  t.rotation = Eigen::Quaterniond(0, 1, 0, 0);
  const msg::TransformStamped tb = round_trip(t);
  same_header(tb.header, t.header);
  EXPECT_EQ(tb.child_frame_id, t.child_frame_id);
  EXPECT_EQ(tb.translation, t.translation);
  EXPECT_EQ(tb.rotation.coeffs(), t.rotation.coeffs());

  msg::PoseStamped p;
  p.header = {7, "map"};
  p.pose.position = {3, 2, 1};
  const msg::PoseStamped pb = round_trip(p);
  same_header(pb.header, p.header);
  EXPECT_EQ(pb.pose.position, p.pose.position);

  msg::TwistStamped w;
  w.header = {8, "map"};
  w.twist.linear = {0.5, 0, -0.1};
  w.twist.angular = {0, 0, 0.3};
  const msg::TwistStamped wb = round_trip(w);
  same_header(wb.header, w.header);
  EXPECT_EQ(wb.twist.linear, w.twist.linear);
  EXPECT_EQ(wb.twist.angular, w.twist.angular);
}

TEST(RosMessages, ImagesAndCameraInfo) {
  DepthFrame f;
  f.shot.camera.width = 4;
  f.shot.camera.height = 3;
  f.shot.utime = 99;
  for (int i = 0; i < 12; ++i) f.depth_mm.push_back(static_cast<uint16_t>(1000 + 997 * i));
  const msg::Image m = to_ros(f, FrameNames(), TimeBase(0));
  const msg::Image b = round_trip(m);
  same_header(b.header, m.header);
  EXPECT_EQ(b.encoding, m.encoding);
  EXPECT_EQ(b.width, m.width);
  EXPECT_EQ(b.height, m.height);
  EXPECT_EQ(b.step, m.step);
  EXPECT_EQ(b.is_bigendian, m.is_bigendian);
  EXPECT_EQ(b.data, m.data);

  const msg::CameraInfo info = to_ros_info(f.shot, FrameNames(), TimeBase(0));
  const msg::CameraInfo ib = round_trip(info);
  same_header(ib.header, info.header);
  EXPECT_EQ(ib.width, info.width);
  EXPECT_EQ(ib.height, info.height);
  EXPECT_EQ(ib.distortion_model, info.distortion_model);
  EXPECT_EQ(ib.D, info.D);
  EXPECT_EQ(ib.K, info.K);
  EXPECT_EQ(ib.R, info.R);
  EXPECT_EQ(ib.P, info.P);
}

TEST(RosMessages, CloudsMarkersPathsStatus) {
  map::StateGrid grid(0.1);
  grid.set_state({1, -2, 3}, map::VoxelState::kOccupied);
  grid.set_state({-40, 7, 0}, map::VoxelState::kOccupied);
  const msg::PointCloud2 c = voxel_cloud(grid, map::VoxelState::kOccupied, "map", 5);
  const msg::PointCloud2 cb = round_trip(c);
  same_header(cb.header, c.header);
  ASSERT_EQ(cb.fields.size(), c.fields.size());
  for (std::size_t i = 0; i < c.fields.size(); ++i) {
    EXPECT_EQ(cb.fields[i].name, c.fields[i].name);
    EXPECT_EQ(cb.fields[i].offset, c.fields[i].offset);
    EXPECT_EQ(cb.fields[i].datatype, c.fields[i].datatype);
    EXPECT_EQ(cb.fields[i].count, c.fields[i].count);
  }
  EXPECT_EQ(cb.data, c.data);
  EXPECT_EQ(cb.point_step, c.point_step);
  EXPECT_EQ(cb.row_step, c.row_step);
  EXPECT_EQ(cb.width, c.width);
  EXPECT_EQ(cb.height, c.height);
  EXPECT_EQ(cb.is_dense, c.is_dense);

  Roadmap r;
  for (int i = 0; i < 4; ++i) {
    RoadmapNode n;
    n.id = i;
    n.position = {0.5 * i, 1.0, 1.2};
    n.score = i;
    n.flags = i == 3 ? RoadmapNode::kGoal : 0;
    r.nodes.push_back(n);
  }
  r.edges = {{0, 1}, {1, 2}, {2, 3}};
  Region g;
  g.id = 4;
  g.class_id = 5;
  g.label = "chair";
  g.centroid = {1, 2, 0.5};
  g.radius = 0.6;
  for (const msg::MarkerArray& a :
       {roadmap_markers(r, "map", 11), region_markers(std::vector<Region>{g}, "map", 12)}) {
    const msg::MarkerArray ab = round_trip(a);
    ASSERT_EQ(ab.markers.size(), a.markers.size());
    for (std::size_t i = 0; i < a.markers.size(); ++i) {
      const msg::Marker &x = a.markers[i], &y = ab.markers[i];
      same_header(y.header, x.header);
      EXPECT_EQ(y.ns, x.ns);
      EXPECT_EQ(y.id, x.id);
      EXPECT_EQ(y.type, x.type);
      EXPECT_EQ(y.action, x.action);
      EXPECT_EQ(y.pose.position, x.pose.position);
      EXPECT_EQ(y.scale, x.scale);
      EXPECT_EQ(y.color.a, x.color.a);
      EXPECT_EQ(y.points, x.points);
      ASSERT_EQ(y.colors.size(), x.colors.size());
      for (std::size_t k = 0; k < x.colors.size(); ++k) EXPECT_EQ(y.colors[k].g, x.colors[k].g);
      EXPECT_EQ(y.text, x.text);
    }
  }
  Roadmap rb;
  ASSERT_TRUE(roadmap_from_markers(round_trip(roadmap_markers(r, "map", 11)), rb));
  EXPECT_EQ(rb.edges.size(), 3u);

  controller::Path p;
  p.waypoints = {{0, 0, 1}, {1, 1, 1}};
  p.yaws = {0.5, -0.5};
  const msg::Path pm = to_ros(p, "map", TimeBase(0));
  controller::Path pb;
  ASSERT_TRUE(path_from_ros(round_trip(pm), pb));
  EXPECT_EQ(pb.waypoints, p.waypoints);
  EXPECT_NEAR(pb.yaws[1], -0.5, 1e-12);

  PlannerStatus s;
  s.utime = 5000000;
  s.planner = "dep";
  s.state = 2;
  s.goal = {1.5, 2.5, 1.0};
  s.best_score = 0.1 + 0.2;
  PlannerStatus sb;
  ASSERT_TRUE(status_from_ros(round_trip(to_ros(s, TimeBase(0))), TimeBase(0), sb));
  EXPECT_EQ(sb.state, s.state);
  EXPECT_EQ(sb.goal, s.goal);
  EXPECT_EQ(sb.best_score, s.best_score);
}
