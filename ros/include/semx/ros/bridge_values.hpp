// What the bridge carries, on the semx side: the content of the semx messages it maps, as plain
// values without LCM. Where a lower layer already has the value (the map's StateGrid and
// EsdfGrid, the controller's Path and Trajectory, the camera model) the bridge uses that; the
// types here are the rest, kept to what the messages say so that the bridge depends on no
// process library but the controller's (whose B-spline it samples).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "semx/core/roadmap_values.hpp"
#include "semx/runtime/pinhole_camera.hpp"

namespace semx::rosbridge {

// ODOMETRY: the body's pose in the world (z up), its world-frame velocity and body-frame rates.
struct VehicleOdometry {
  int64_t utime = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world <- body
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               // m/s, world frame
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       // rad/s, body frame

  Eigen::Isometry3d pose() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = orientation.toRotationMatrix();
    T.translation() = position;
    return T;
  }
};

// One capture of the camera (camera_info_t): when, which frame, the model, where.
struct CameraShot {
  int64_t utime = 0;
  int64_t frame_id = 0;  // depth, labels and RGB of one capture share it
  runtime::PinholeCamera camera;
  Eigen::Isometry3d T_world_optical = Eigen::Isometry3d::Identity();
};

// CAMERA_DEPTH decoded: z-depth in millimetres, row-major, with semx's reserved values
// (runtime::kDepthInvalid, runtime::kDepthNoReturn).
struct DepthFrame {
  CameraShot shot;
  std::vector<uint16_t> depth_mm;
};

// CAMERA_LABELS decoded: per pixel a class id (runtime/semantic_classes.hpp) and an instance id.
struct LabelFrame {
  CameraShot shot;
  std::vector<uint16_t> classes;
  std::vector<uint16_t> instances;
};

// CAMERA_RGB decoded: 8-bit R, G, B interleaved.
struct RgbFrame {
  CameraShot shot;
  std::vector<uint8_t> rgb;
};

// ROADMAP and SEMANTIC_REGIONS: the values the viewer draws too.
using core::Region;
using core::Roadmap;
using core::RoadmapNode;

// PLANNER_STATUS.
struct PlannerStatus {
  int64_t utime = 0;
  std::string planner;
  int state = 0;  // core::PlannerState's values
  std::string reason;
  int64_t iteration = 0;
  int num_nodes = 0;
  int num_edges = 0;
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  double best_gain = 0.0;
  double best_reward = 0.0;
  double best_score = 0.0;
  double total_ms = 0.0;
  double charged_s = 0.0;
};

// CONTROL_CMD as sent (the controller's Command has no ACCELERATION or YAW_RATE mode).
struct VehicleCommand {
  enum class Mode { kHold = 0, kVelocity = 1, kAcceleration = 2 };
  enum class YawMode { kAngle = 0, kRate = 1 };
  int64_t utime = 0;
  Mode mode = Mode::kHold;
  Eigen::Vector3d setpoint = Eigen::Vector3d::Zero();  // world frame, m/s or m/s^2
  YawMode yaw_mode = YawMode::kAngle;
  double yaw = 0.0;
  double yaw_rate = 0.0;
};

}  // namespace semx::rosbridge
