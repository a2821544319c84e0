#include "bridge_node.hpp"

#include <iostream>

#include "bridge_messages.hpp"
#include "controller_messages.hpp"
#include "map_client.hpp"
#include "map_messages.hpp"
#include "semx/ros/camera_conversion.hpp"
#include "semx/ros/cloud_conversion.hpp"
#include "semx/ros/marker_conversion.hpp"
#include "semx/ros/odometry_conversion.hpp"
#include "semx/ros/path_conversion.hpp"
#include "semx/ros/setpoint_conversion.hpp"
#include "semx/ros/status_conversion.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::rosbridge {

namespace {

int64_t period_us(double hz) { return static_cast<int64_t>(1e6 / hz); }

bool same_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < 1e-9;
}

}  // namespace

BridgeNode::BridgeNode(runtime::NodeOptions options, const BridgeConfig& config)
    : config_(config), node_(std::move(options)), ros_(config) {
  map::MapClientOptions mo;
  mo.apply = map::MapClientOptions::Apply::kImmediately;  // a viewer: latest map, no lockstep
  mo.quiet = true;
  map_ = std::make_unique<map::MapClient>(node_, mo);
  if (config_.mode == BridgeMode::kMirror) subscribe_mirror();
  subscribe_plans();
  if (config_.mode == BridgeMode::kExternal) subscribe_commands();
  node_.on_tick([this](int64_t, int64_t utime) { on_tick(utime); });
  node_.set_state(runtime::NodeState::kRunning, "waiting for the ROS master");
}

BridgeNode::~BridgeNode() { ros_.stop(); }

TimeBase BridgeNode::time() const {
  return config_.mode == BridgeMode::kMirror ? TimeBase(0) : ros_.time();
}

void BridgeNode::subscribe_mirror() {
  const bool camera = config_.camera;
  node_.subscribe<semx::odometry_t>(
      semx::channels::ODOMETRY, [this](const semx::odometry_t& m) { on_odometry(from_message(m)); },
      controller::accept_odometry);
  if (!camera) return;
  // Images are decoded only while ROS listens (and once for the camera's mount).
  node_.skip_unless(semx::channels::CAMERA_DEPTH,
                    [this](int64_t) { return ros_.wants(OutTopic::kDepth) || !camera_mount_; });
  node_.subscribe<semx::depth_image_t>(
      semx::channels::CAMERA_DEPTH,
      [this](const semx::depth_image_t& m) {
        DepthFrame f;
        if (!from_message(m, f).empty()) return;
        if (auto body = body_pose_at(f.shot.utime)) {
          const Eigen::Isometry3d mount = camera_link_in_body(*body, f.shot.T_world_optical);
          if (!camera_mount_ || !same_pose(*camera_mount_, mount)) {
            camera_mount_ = mount;
            ros_.set_static_transform(camera_transform(f.shot, *body, config_.frames, time()));
            ros_.set_static_transform(optical_transform(config_.frames, time().to_ros_ns(f.shot.utime)));
          }
        }
        if (!ros_.wants(OutTopic::kDepth)) return;
        ros_.send({OutTopic::kDepth, ImagePair{to_ros(f, config_.frames, time()),
                                               to_ros_info(f.shot, config_.frames, time())}});
      },
      [](const semx::depth_image_t& m) { return accept_camera(m.info); });
  node_.skip_unless(semx::channels::CAMERA_LABELS, [this](int64_t) { return ros_.wants(OutTopic::kLabels); });
  node_.subscribe<semx::label_image_t>(
      semx::channels::CAMERA_LABELS,
      [this](const semx::label_image_t& m) {
        LabelFrame f;
        if (!from_message(m, f).empty()) return;
        ros_.send({OutTopic::kLabels, ImagePair{to_ros(f, config_.frames, time()),
                                                to_ros_info(f.shot, config_.frames, time())}});
      },
      [](const semx::label_image_t& m) { return accept_camera(m.info); });
  node_.skip_unless(semx::channels::CAMERA_RGB, [this](int64_t) { return ros_.wants(OutTopic::kRgb); });
  node_.subscribe<semx::rgb_image_t>(
      semx::channels::CAMERA_RGB,
      [this](const semx::rgb_image_t& m) {
        RgbFrame f;
        if (!from_message(m, f).empty()) return;
        ros_.send({OutTopic::kRgb, ImagePair{to_ros(f, config_.frames, time()),
                                             to_ros_info(f.shot, config_.frames, time())}});
      },
      [](const semx::rgb_image_t& m) { return accept_camera(m.info); });
}

void BridgeNode::subscribe_plans() {
  if (config_.mode == BridgeMode::kExternal) {
    // Its own ODOMETRY, echoed by the group: the vehicle's heading and height for the outputs.
    node_.subscribe<semx::odometry_t>(
        semx::channels::ODOMETRY, [this](const semx::odometry_t& m) { on_odometry(from_message(m)); },
        controller::accept_odometry);
  }
  node_.skip_unless(semx::channels::ESDF_LOCAL,
                    [this](int64_t utime) { return ros_.wants(OutTopic::kEsdf) && utime >= next_esdf_utime_; });
  node_.subscribe<semx::esdf_local_t>(semx::channels::ESDF_LOCAL, [this](const semx::esdf_local_t& m) {
    map::EsdfGrid grid;
    if (!map::from_message(m, grid) || odometry_.empty() || !time().known()) return;
    next_esdf_utime_ = m.utime + period_us(config_.rates.esdf_hz);
    const double z = odometry_.back().position.z() + config_.rates.esdf_slice_offset;
    ros_.send({OutTopic::kEsdf, esdf_slice(grid, z, config_.frames.map, time().to_ros_ns(m.utime))});
  });
  node_.subscribe<semx::roadmap_t>(
      semx::channels::ROADMAP,
      [this](const semx::roadmap_t& m) {
        if (!time().known()) return;
        ros_.send({OutTopic::kRoadmap, roadmap_markers(from_message(m), config_.frames.map, time().to_ros_ns(m.utime))});
      },
      accept_roadmap);
  node_.subscribe<semx::semantic_regions_t>(
      semx::channels::SEMANTIC_REGIONS,
      [this](const semx::semantic_regions_t& m) {
        if (!time().known()) return;
        ros_.send({OutTopic::kRegions, region_markers(from_message(m), config_.frames.map, time().to_ros_ns(m.utime))});
      },
      accept_regions);
  node_.subscribe<semx::path_t>(
      semx::channels::PLAN_PATH,
      [this](const semx::path_t& m) {
        if (!time().known()) return;
        ros_.send({OutTopic::kPath, to_ros(controller::to_path(m), config_.frames.map, time())});
      },
      controller::accept_path);
  node_.subscribe<semx::trajectory_t>(
      semx::channels::TRAJECTORY,
      [this](const semx::trajectory_t& m) {
        trajectory_ = controller::to_trajectory(m);
        if (!time().known()) return;
        ros_.send({OutTopic::kTrajectory, to_ros(*trajectory_, config_.rates.trajectory_dt, config_.frames.map, time())});
      },
      accept_trajectory);
  node_.subscribe<semx::planner_status_t>(
      semx::channels::PLANNER_STATUS,
      [this](const semx::planner_status_t& m) {
        if (!time().known()) return;
        ros_.send({OutTopic::kStatus, to_ros(from_message(m), time())});
      },
      accept_status);
}

void BridgeNode::subscribe_commands() {
  const std::string& mode = config_.setpoints.mode;
  if (mode != "velocity" && mode != "both") return;
  node_.subscribe<semx::control_cmd_t>(
      semx::channels::CONTROL_CMD,
      [this](const semx::control_cmd_t& m) {
        if (!time().known()) return;
        std::optional<double> yaw;
        if (!odometry_.empty()) yaw = quaternion_yaw(odometry_.back().orientation);
        ros_.send({OutTopic::kVelocitySetpoint, velocity_setpoint(from_message(m), yaw, config_.setpoints.conversion,
                                                                  config_.frames.map, time())});
      },
      accept_command);
}

void BridgeNode::on_odometry(const VehicleOdometry& o) {
  odometry_.push_back(o);
  while (odometry_.size() > 1 && odometry_.back().utime - odometry_.front().utime > 1000000) odometry_.pop_front();
  if (config_.mode != BridgeMode::kMirror) return;
  ros_.send_transform(body_transform(o, config_.frames, time()));
  if (ros_.wants(OutTopic::kOdom)) ros_.send({OutTopic::kOdom, to_ros(o, config_.frames, time())});
}

std::optional<Eigen::Isometry3d> BridgeNode::body_pose_at(int64_t utime) const {
  const VehicleOdometry* best = nullptr;
  for (const auto& o : odometry_) {
    if (!best || std::llabs(o.utime - utime) < std::llabs(best->utime - utime)) best = &o;
  }
  // The simulator sends the odometry of a camera frame's tick with it; 20 ms covers a lost one.
  if (!best || std::llabs(best->utime - utime) > 20000) return std::nullopt;
  return best->pose();
}

void BridgeNode::on_tick(int64_t utime) {
  if (config_.mode == BridgeMode::kMirror && config_.publish_clock) ros_.set_clock(time().to_ros_ns(utime));
  publish_map(utime);
  if (config_.mode == BridgeMode::kExternal && time().known() &&
      (config_.setpoints.mode == "position" || config_.setpoints.mode == "both") && utime >= next_position_setpoint_) {
    // MAVROS leaves offboard mode when setpoints stop (< 2 Hz): a stream at 20 Hz, holding the
    // vehicle's position while there is no trajectory.
    next_position_setpoint_ = utime + 50000;
    if (trajectory_) {
      ros_.send({OutTopic::kPositionSetpoint, position_setpoint(*trajectory_, utime, config_.setpoints.conversion,
                                                                config_.frames.map, time())});
    } else if (!odometry_.empty()) {
      msg::PoseStamped hold;
      hold.header.stamp_ns = time().to_ros_ns(utime);
      hold.header.frame_id = config_.frames.map;
      hold.pose.position = odometry_.back().position;
      hold.pose.orientation = odometry_.back().orientation;
      ros_.send({OutTopic::kPositionSetpoint, hold});
    }
  }
}

void BridgeNode::publish_map(int64_t utime) {
  if (!map_->in_sync() || !time().known()) return;
  const map::StateGrid& grid = map_->mirror().grid();
  if (ros_.wants(OutTopic::kMap) && utime >= next_map_utime_ && grid.changes() != map_changes_sent_) {
    next_map_utime_ = utime + period_us(config_.rates.map_hz);
    map_changes_sent_ = grid.changes();
    ros_.send({OutTopic::kMap, voxel_cloud(grid, map::VoxelState::kOccupied, config_.frames.map,
                                           time().to_ros_ns(utime), config_.rates.map_max_z)});
  }
  if (ros_.wants(OutTopic::kMapFree) && utime >= next_free_utime_) {
    next_free_utime_ = utime + period_us(config_.rates.map_free_hz);
    ros_.send({OutTopic::kMapFree, voxel_cloud(grid, map::VoxelState::kFree, config_.frames.map,
                                               time().to_ros_ns(utime), config_.rates.map_max_z)});
  }
}

void BridgeNode::forward_inputs() {
  for (auto& item : ros_.take_inputs()) {
    std::visit(
        [this](auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, VehicleOdometry>) {
            node_.publish(semx::channels::ODOMETRY, to_message(v));
          } else if constexpr (std::is_same_v<T, DepthFrame>) {
            node_.publish(semx::channels::CAMERA_DEPTH, to_message(v));
          } else {
            node_.publish(semx::channels::CAMERA_LABELS, to_message(v));
          }
        },
        item);
  }
}

void BridgeNode::external_clock() {
  if (!ros_.time_known()) return;
  const int64_t ns = ros_.sensor_time_ns(0.2);
  int64_t utime = 0;
  if (ns <= 0 || !ros_.time().to_utime(ns, utime)) return;
  const int64_t period = static_cast<int64_t>(config_.clock_period_s * 1e6);
  const int64_t tick = utime / period;
  if (tick <= last_tick_) return;
  last_tick_ = tick;
  node_.publish(semx::channels::SIM_CLOCK, clock_message(tick, tick * period, period));
}

void BridgeNode::update_state() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_state_) return;
  next_state_ = now + std::chrono::seconds(1);
  const RosCounters c = ros_.counters();
  std::string detail = std::string(to_string(config_.mode)) + ": published " + std::to_string(c.published) +
                       ", dropped " + std::to_string(c.dropped);
  if (config_.mode == BridgeMode::kExternal) {
    detail += ", inputs " + std::to_string(c.inputs) + ", refused " + std::to_string(c.rejected) +
              ", without transform " + std::to_string(c.tf_missing);
  }
  if (ros_.connected()) {
    node_.set_state(runtime::NodeState::kRunning, detail);
  } else {
    node_.set_state(runtime::NodeState::kDegraded, "ROS master unreachable (reconnecting); " + detail);
  }
}

int BridgeNode::run() {
  ros_.start();
  int rc = 0;
  while (!node_.stopped()) {
    if (node_.spin_once(config_.mode == BridgeMode::kExternal ? 2 : 5) < 0) {
      node_.set_state(runtime::NodeState::kFailed, "LCM provider failed");
      rc = 1;
      break;
    }
    node_.drain();
    if (config_.mode == BridgeMode::kExternal) {
      forward_inputs();
      external_clock();
    }
    update_state();
  }
  if (rc == 0) node_.set_state(runtime::NodeState::kStopping, "signal");
  ros_.stop();
  const RosCounters c = ros_.counters();
  std::cout << "semx-ros-bridge: published " << c.published << ", dropped " << c.dropped << ", connections "
            << c.connects << ", inputs " << c.inputs << ", refused " << c.rejected << ", without transform "
            << c.tf_missing << std::endl;
  return rc;
}

}  // namespace semx::rosbridge
