// semx-ros-bridge's configuration (ros/config/bridge.yaml lists every key with its default; a
// test checks the file against this struct).
#pragma once

#include <string>

#include "semx/ros/frames.hpp"
#include "semx/ros/setpoint_conversion.hpp"
#include "semx/runtime/config.hpp"

namespace semx::rosbridge {

enum class BridgeMode {
  kMirror,    // a simulated semx set runs: publish its vehicle, camera, map and plans to ROS, /clock
  kExternal,  // no semx simulator: ROS sensors in (odometry, depth, labels), semx's commands out
};

struct OutputTopics {
  std::string odom = "/semx/odom";
  std::string map = "/semx/map";
  std::string map_free = "/semx/map_free";  // published only while someone subscribes
  std::string esdf_slice = "/semx/esdf_slice";
  std::string roadmap = "/semx/roadmap";
  std::string regions = "/semx/regions";
  std::string path = "/semx/path";
  std::string trajectory = "/semx/trajectory";
  std::string planner_status = "/semx/planner_status";
  std::string depth = "/semx/camera/depth/image_raw";
  std::string depth_info = "/semx/camera/depth/camera_info";
  std::string labels = "/semx/camera/labels/image_raw";
  std::string labels_info = "/semx/camera/labels/camera_info";
  std::string rgb = "/semx/camera/rgb/image_raw";
  std::string rgb_info = "/semx/camera/rgb/camera_info";
};

// External mode's inputs. The defaults are the mirror's own topics, so a bag recorded from a
// simulated run plays straight into an external set (docs/ros.md).
struct InputTopics {
  std::string odom = "/semx/odom";
  std::string odom_type = "odometry";  // odometry (nav_msgs/Odometry) | pose (geometry_msgs/PoseStamped)
  std::string depth = "/semx/camera/depth/image_raw";
  std::string camera_info = "/semx/camera/depth/camera_info";
  std::string labels = "/semx/camera/labels/image_raw";  // "" for none: semantics then sees no objects
  double min_range = 0.5;     // m, the depth camera's (CameraInfo has none)
  double max_range = 5.0;     // m
  double tf_timeout_s = 0.5;  // ROS time an image waits for the camera's transform before it is dropped
  bool publish_body_tf = false;  // publish map -> base_link from the odometry (when the vehicle does not)
};

// External mode: semx's commands as MAVROS offboard setpoints.
struct SetpointOutput {
  std::string mode = "velocity";  // velocity | position | both | none
  std::string velocity_topic = "/mavros/setpoint_velocity/cmd_vel";
  std::string position_topic = "/mavros/setpoint_position/local";
  SetpointConfig conversion;
};

struct BridgeRates {
  double map_hz = 1.0;       // occupied-voxel cloud, per second of message time
  double map_free_hz = 0.2;  // free-voxel cloud, while subscribed
  double esdf_hz = 2.0;      // ESDF slice
  double trajectory_dt = 0.1;   // s between the trajectory's samples
  double esdf_slice_offset = 0.0;  // m above the vehicle's height
  // m: the map clouds leave out voxels whose centre is higher (a ceiling hides a room from above,
  // rviz's default view); a large value keeps every voxel.
  double map_max_z = 2.0;
};

struct BridgeConfig {
  BridgeMode mode = BridgeMode::kMirror;
  std::string node_name = "semx_ros_bridge";  // the ROS node's name
  FrameNames frames;
  OutputTopics out;
  InputTopics in;
  SetpointOutput setpoints;
  BridgeRates rates;
  bool camera = true;       // mirror: publish the camera's images (depth, labels, RGB when sent)
  bool publish_clock = true;   // mirror: /clock from SIM_CLOCK and /use_sim_time set true
  int queue_frames = 8;     // per topic: images queued for ROS before the oldest is dropped
  int queue_messages = 256; // odometry, transforms and the rest
  double master_check_s = 1.0;  // wall seconds between checks that the ROS master answers
  double clock_period_s = 0.01; // external: SIM_CLOCK tick period (ROS time)
};

void load(runtime::ConfigMap& m, BridgeConfig& c);
const char* to_string(BridgeMode m);

}  // namespace semx::rosbridge
