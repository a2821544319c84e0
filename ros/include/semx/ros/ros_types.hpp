// ROS 1 messages as plain structs: the field names and meanings of sensor_msgs, nav_msgs,
// geometry_msgs, visualization_msgs and diagnostic_msgs (Noetic), with no ROS header behind
// them. The bridge library fills and reads these; the node copies them member by member into
// the real messages (ros/node/ros_messages.cpp). So every rule of the mapping (frames, units,
// encodings, byte layouts, colours) lives in a library that builds and is tested on a machine
// without ROS, and the node's copy is the only code that needs roscpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace semx::rosbridge::msg {

// std_msgs/Header without seq (roscpp fills it). ROS time as nanoseconds since its epoch.
struct Header {
  int64_t stamp_ns = 0;
  std::string frame_id;
};

// geometry_msgs/Pose (Point + Quaternion).
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

// geometry_msgs/Twist.
struct Twist {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
};

// nav_msgs/Odometry: the pose in header.frame_id, the twist in child_frame_id (the body).
// Covariances are left at zero ("unknown" for most consumers); the bridge neither sets nor reads them.
struct Odometry {
  Header header;
  std::string child_frame_id;
  Pose pose;
  Twist twist;
};

// geometry_msgs/TransformStamped: child_frame_id's pose in header.frame_id.
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// geometry_msgs/PoseStamped, geometry_msgs/TwistStamped.
struct PoseStamped {
  Header header;
  Pose pose;
};
struct TwistStamped {
  Header header;
  Twist twist;
};

// nav_msgs/Path.
struct Path {
  Header header;
  std::vector<PoseStamped> poses;
};

// sensor_msgs/PointField and PointCloud2.
struct PointField {
  static constexpr uint8_t INT8 = 1, UINT8 = 2, INT16 = 3, UINT16 = 4, INT32 = 5, UINT32 = 6, FLOAT32 = 7,
                           FLOAT64 = 8;
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = FLOAT32;
  uint32_t count = 1;
};
struct PointCloud2 {
  Header header;
  uint32_t height = 1;
  uint32_t width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  std::vector<uint8_t> data;
  bool is_dense = true;
};

// sensor_msgs/Image.
struct Image {
  Header header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string encoding;  // sensor_msgs/image_encodings names: "16UC1", "32FC1", "rgb8", ...
  bool is_bigendian = false;
  uint32_t step = 0;  // bytes per row
  std::vector<uint8_t> data;
};

// sensor_msgs/CameraInfo (binning and ROI left at their zero defaults: full resolution).
struct CameraInfo {
  Header header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string distortion_model;
  std::vector<double> D;
  std::array<double, 9> K{};
  std::array<double, 9> R{};
  std::array<double, 12> P{};
};

// std_msgs/ColorRGBA.
struct Color {
  float r = 0, g = 0, b = 0, a = 1;
};

// visualization_msgs/Marker and MarkerArray.
struct Marker {
  static constexpr int32_t ARROW = 0, CUBE = 1, SPHERE = 2, CYLINDER = 3, LINE_STRIP = 4, LINE_LIST = 5,
                           CUBE_LIST = 6, SPHERE_LIST = 7, POINTS = 8, TEXT_VIEW_FACING = 9;
  static constexpr int32_t ADD = 0, DELETE = 2, DELETEALL = 3;
  Header header;
  std::string ns;
  int32_t id = 0;
  int32_t type = SPHERE;
  int32_t action = ADD;
  Pose pose;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Color color;
  int64_t lifetime_ns = 0;  // 0: until replaced
  bool frame_locked = false;
  std::vector<Eigen::Vector3d> points;
  std::vector<Color> colors;
  std::string text;
};
struct MarkerArray {
  std::vector<Marker> markers;
};

// diagnostic_msgs/DiagnosticStatus and DiagnosticArray.
struct KeyValue {
  std::string key;
  std::string value;
};
struct DiagnosticStatus {
  static constexpr int8_t OK = 0, WARN = 1, ERROR = 2, STALE = 3;
  int8_t level = OK;
  std::string name;
  std::string message;
  std::string hardware_id;
  std::vector<KeyValue> values;
};
struct DiagnosticArray {
  Header header;
  std::vector<DiagnosticStatus> status;
};

}  // namespace semx::rosbridge::msg
