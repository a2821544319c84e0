// The plain structs of ros_types.hpp <-> the real ROS 1 messages, member by member: the only
// code of the bridge that includes ROS message headers besides the ROS thread (ros_side.hpp).
// Every rule of the mapping is in semx_ros; these copy.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

::ros::Time to_ros_time(int64_t ns);
int64_t from_ros_time(const ::ros::Time& t);

nav_msgs::Odometry to_ros_msg(const msg::Odometry& m);
geometry_msgs::TransformStamped to_ros_msg(const msg::TransformStamped& m);
geometry_msgs::PoseStamped to_ros_msg(const msg::PoseStamped& m);
geometry_msgs::TwistStamped to_ros_msg(const msg::TwistStamped& m);
nav_msgs::Path to_ros_msg(const msg::Path& m);
sensor_msgs::PointCloud2 to_ros_msg(const msg::PointCloud2& m);
sensor_msgs::Image to_ros_msg(const msg::Image& m);
sensor_msgs::CameraInfo to_ros_msg(const msg::CameraInfo& m);
visualization_msgs::MarkerArray to_ros_msg(const msg::MarkerArray& m);
diagnostic_msgs::DiagnosticArray to_ros_msg(const msg::DiagnosticArray& m);

msg::Odometry from_ros_msg(const nav_msgs::Odometry& m);
msg::TransformStamped from_ros_msg(const geometry_msgs::TransformStamped& m);
msg::PoseStamped from_ros_msg(const geometry_msgs::PoseStamped& m);
msg::TwistStamped from_ros_msg(const geometry_msgs::TwistStamped& m);
msg::Path from_ros_msg(const nav_msgs::Path& m);
msg::PointCloud2 from_ros_msg(const sensor_msgs::PointCloud2& m);
msg::Image from_ros_msg(const sensor_msgs::Image& m);
msg::CameraInfo from_ros_msg(const sensor_msgs::CameraInfo& m);
msg::MarkerArray from_ros_msg(const visualization_msgs::MarkerArray& m);
msg::DiagnosticArray from_ros_msg(const diagnostic_msgs::DiagnosticArray& m);

}  // namespace semx::rosbridge
