// semx-ros-bridge's LCM side: a runtime::Node like every process's, which never waits for ROS.
//
// Mirror mode (a simulated set runs): reads ODOMETRY, the camera, the map (a MapClient), the
// ESDF window, ROADMAP, SEMANTIC_REGIONS, PLAN_PATH, TRAJECTORY and PLANNER_STATUS, converts
// what ROS subscribers want, and queues it for the ROS thread (ros_side.hpp); SIM_CLOCK becomes
// /clock. It is no lockstep participant: the clock never waits for it.
// External mode (no semx simulator): the ROS thread's odometry and camera frames go out as
// ODOMETRY, CAMERA_DEPTH and CAMERA_LABELS, SIM_CLOCK (REALTIME) follows the sensors' stamps,
// and CONTROL_CMD / TRAJECTORY go to ROS as setpoints; the map and plans are mirrored as above.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>

#include "ros_side.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/map/esdf_grid.hpp"
#include "semx/ros/bridge_config.hpp"
#include "semx/ros/bridge_values.hpp"
#include "semx/runtime/node.hpp"

namespace semx::map {
class MapClient;
}

namespace semx::rosbridge {

class BridgeNode {
 public:
  BridgeNode(runtime::NodeOptions options, const BridgeConfig& config);
  ~BridgeNode();

  runtime::Node& node() { return node_; }
  int run();

 private:
  void subscribe_mirror();
  void subscribe_plans();
  void subscribe_commands();
  void on_tick(int64_t utime);
  void on_odometry(const VehicleOdometry& o);
  void publish_map(int64_t utime);
  void forward_inputs();
  void external_clock();
  void update_state();
  TimeBase time() const;
  std::optional<Eigen::Isometry3d> body_pose_at(int64_t utime) const;

  BridgeConfig config_;
  runtime::Node node_;
  RosSide ros_;
  std::unique_ptr<map::MapClient> map_;
  std::deque<VehicleOdometry> odometry_;  // the last second, to pair camera frames with the body's pose
  std::optional<Eigen::Isometry3d> camera_mount_;  // base_link <- camera_link last sent
  int64_t next_map_utime_ = 0;
  int64_t next_free_utime_ = 0;
  int64_t next_esdf_utime_ = 0;
  uint64_t map_changes_sent_ = ~uint64_t{0};
  std::optional<controller::Trajectory> trajectory_;
  int64_t next_position_setpoint_ = 0;
  int64_t last_tick_ = -1;
  std::chrono::steady_clock::time_point next_state_;
};

}  // namespace semx::rosbridge
