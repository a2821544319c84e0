// The vehicle: a point-mass quadrotor with a yaw, first-order velocity response and limits,
// whose 0.5 x 0.5 x 0.3 m body box (yawed) is tested against every solid each step. Roll and
// pitch are not modelled: the body (and the camera on it) stays level, as on a stabilised
// mount. Dynamics in docs/simulator.md.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/core/byte_io.hpp"
#include "semx/runtime/config.hpp"
#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct VehicleConfig {
  double velocity_time_constant = 0.3;  // s: v̇ = (v_cmd - v) / τ before the limits
  double max_speed_xy = 1.5;            // m/s, horizontal speed
  double max_speed_z = 1.0;             // m/s
  double max_acceleration = 3.0;        // m/s², norm
  double max_yaw_rate = 1.5;            // rad/s
  double yaw_time_constant = 0.1;       // s: first-order yaw-rate response
  double yaw_gain = 2.0;                // 1/s: yaw-angle mode commands rate = gain · error
  double hold_gain = 1.5;               // 1/s: hold mode commands v = gain · (p_hold - p)
  // A command beyond a limit by at most this factor is saturated; beyond it, rejected.
  double command_tolerance = 1.25;
  Eigen::Vector3d body_size = kVehicleSize;
};
void load(runtime::ConfigMap& m, VehicleConfig& c);

// Mirrors semx::control_cmd_t.
struct ControlCommand {
  enum Mode : int8_t { kHold = 0, kVelocity = 1, kAcceleration = 2 };
  enum YawMode : int8_t { kYawAngle = 0, kYawRate = 1 };
  int mode = kHold;
  Eigen::Vector3d setpoint = Eigen::Vector3d::Zero();  // world: m/s or m/s²
  int yaw_mode = kYawRate;
  double yaw = 0.0;       // rad (kYawAngle)
  double yaw_rate = 0.0;  // rad/s (kYawRate)

  static ControlCommand velocity(const Eigen::Vector3d& v, double yaw_rate = 0.0);
  static ControlCommand velocity_yaw(const Eigen::Vector3d& v, double yaw);
  static ControlCommand acceleration(const Eigen::Vector3d& a, double yaw_rate = 0.0);
  static ControlCommand hold();
};

struct VehicleState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      // world
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // world, over the last step
  double yaw = 0.0;                                        // rad, wrapped to (-π, π]
  double yaw_rate = 0.0;                                   // rad/s

  Eigen::Quaterniond orientation() const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  }
  Eigen::Isometry3d body_pose() const;
  // The camera's optical frame in the world: at the body centre, looking along body x.
  Eigen::Isometry3d camera_pose() const;
};

struct CommandResult {
  bool accepted = true;
  std::string reason;  // why it was rejected
};

struct StepReport {
  bool blocked = false;          // the move would have entered a solid; the vehicle stopped (moved
                                 // without turning when only the turn would have)
  bool collision_start = false;  // first blocked step of a contact (what collisions() counts)
  int solid = -1;                // the solid hit
};

class Quadrotor {
 public:
  // Starts at the world's start pose, hovering. `world` must outlive the vehicle.
  Quadrotor(const World& world, const VehicleConfig& config);

  // Validates and applies a command. A rejected command (non-finite value, unknown mode,
  // beyond command_tolerance x a limit) is counted and the vehicle holds its position.
  CommandResult command(const ControlCommand& cmd);
  // Holds the current position (e.g. when commands stop arriving).
  void hold();
  StepReport step(double dt);

  const VehicleState& state() const { return state_; }
  void set_state(const VehicleState& s);
  const VehicleConfig& config() const { return config_; }
  const ControlCommand& active_command() const { return cmd_; }
  // Index of a solid the body overlaps at a pose, or -1.
  int body_hit(const Eigen::Vector3d& position, double yaw) const;

  int64_t collisions() const { return collisions_; }
  int64_t blocked_steps() const { return blocked_steps_; }
  int64_t rejected_commands() const { return rejected_; }

  // Everything that changes while it flies (state, command, contact, counters), bit for bit.
  void save(core::ByteWriter& w) const;
  // Throws std::out_of_range when the bytes run out.
  void restore(core::ByteReader& r);

 private:
  const World& world_;
  VehicleConfig config_;
  std::vector<Aabb> solid_bounds_;
  VehicleState state_;
  ControlCommand cmd_;
  Eigen::Vector3d hold_position_;
  bool in_contact_ = false;
  int contact_solid_ = -1;
  static constexpr double kContactMargin = 0.01;  // m
  int64_t collisions_ = 0, blocked_steps_ = 0, rejected_ = 0;
};

}  // namespace semx::simulator
