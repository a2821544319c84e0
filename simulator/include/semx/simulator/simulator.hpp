// The simulator: owns a world, the vehicle and its sensors, and advances simulated time in
// fixed integer-microsecond steps, telling the caller which sensor outputs fall due. It knows
// no LCM and no wall clock; with a fixed seed and the same command sequence it reproduces every
// output bit for bit. A node drives it as:
//
//   Simulator sim(load_world(path), config);
//   for (;;) {
//     if (new command) sim.command(cmd);
//     StepResult r = sim.step();
//     if (r.imu) publish(*r.imu);
//     if (r.odometry) publish(*r.odometry);
//     if (r.camera_due) { sim.render_camera(frame); publish(frame); }
//     if (r.collision) publish(*r.collision);
//   }
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "semx/runtime/config.hpp"
#include "semx/runtime/pinhole_camera.hpp"
#include "semx/simulator/camera_frame.hpp"
#include "semx/simulator/imu.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "semx/simulator/sensor_noise.hpp"
#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct SimulatorConfig {
  int64_t step_us = 1000;  // physics step; sensor times are rounded up to it
  uint64_t seed = 1;
  runtime::PinholeCamera camera;
  double camera_rate_hz = 30.0;
  double odometry_rate_hz = 100.0;
  // No valid command for this long puts the vehicle in position hold (0 = never).
  int64_t command_timeout_us = 500000;
  int cylinder_segments = 32;
  VehicleConfig vehicle;
  ImuConfig imu;
  DepthNoiseConfig depth_noise;
  DetectionNoiseConfig detection_noise;
};
// Keys: step_us, seed, camera_rate_hz, odometry_rate_hz, command_timeout_us,
// cylinder_segments, camera{width, height, fx, fy, cx, cy, min_range, max_range}, vehicle{...},
// imu{...}, depth_noise{...}, detection_noise{...} (docs/simulator.md).
void load(runtime::ConfigMap& m, SimulatorConfig& c);

struct OdometrySample {
  int64_t utime = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world <- body
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               // world
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       // body
};

struct CollisionEvent {
  int64_t utime = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int solid = -1;
  int64_t count = 0;  // collisions so far, this one included
};

struct StepResult {
  int64_t utime = 0;        // simulated time after the step
  bool camera_due = false;  // call render_camera() for the frame of this instant
  std::optional<ImuSample> imu;
  std::optional<OdometrySample> odometry;
  std::optional<CollisionEvent> collision;
  bool command_timed_out = false;  // the vehicle switched to hold in this step
};

class Simulator {
 public:
  Simulator(World world, const SimulatorConfig& config);
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Applies a command now; see Quadrotor::command for validation.
  CommandResult command(const ControlCommand& cmd);
  // Advances one step_us and reports what fell due at the new time.
  StepResult step();
  // Renders the camera at the current state. frame_id is the index of the last camera sample
  // that fell due, and it alone seeds the frame's noise.
  void render_camera(CameraFrame& out, unsigned channels = kRenderAll);
  OdometrySample odometry() const;

  int64_t time_us() const { return time_us_; }
  const World& world() const { return *world_; }
  const SimulatorConfig& config() const { return config_; }
  const Quadrotor& vehicle() const { return *vehicle_; }
  Quadrotor& vehicle() { return *vehicle_; }
  Rasterizer& rasterizer() { return *rasterizer_; }
  int64_t camera_frames_due() const { return camera_count_; }
  int64_t command_timeouts() const { return timeouts_; }

  // Everything step() changes (time, sensor counters, the vehicle, the IMU's generator and
  // biases), so a simulator restarted after a crash continues the same episode: restored into a
  // Simulator of the same world and config, it steps on exactly as this one would have.
  std::vector<uint8_t> save_state() const;
  // Throws std::runtime_error when the bytes are not a state of this world, seed and step.
  void restore_state(const std::vector<uint8_t>& bytes);

 private:
  // Time of sample k of a sensor at `rate_hz`, rounded up to the step grid.
  int64_t due_time(int64_t k, double rate_hz) const;

  std::unique_ptr<World> world_;  // stable address: the vehicle and rasteriser refer to it
  SimulatorConfig config_;
  std::unique_ptr<Quadrotor> vehicle_;
  std::unique_ptr<Rasterizer> rasterizer_;
  ImuModel imu_;
  int64_t time_us_ = 0;
  int64_t camera_count_ = 0, imu_count_ = 0, odom_count_ = 0;
  int64_t last_command_us_ = 0;
  bool timed_out_ = false;
  int64_t timeouts_ = 0;
};

}  // namespace semx::simulator
