#include "semx/simulator/simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "semx/core/random.hpp"

namespace semx::simulator {
namespace {

// Independent random streams drawn from the one seed.
enum Stream : uint64_t { kImuStream = 1, kDepthStream = 2, kDetectionStream = 3 };

void load_camera(runtime::ConfigMap& m, runtime::PinholeCamera& c) {
  m.get("width", c.width, 1, 8192);
  m.get("height", c.height, 1, 8192);
  // A principal point not given follows the image size, so changing only the size stays sane.
  c.cx = 0.5 * c.width;
  c.cy = 0.5 * c.height;
  m.get("fx", c.fx, 1.0, 1e5);
  m.get("fy", c.fy, 1.0, 1e5);
  m.get("cx", c.cx, -1e5, 1e5);
  m.get("cy", c.cy, -1e5, 1e5);
  m.get("min_range", c.min_range, 0.0, 60.0);
  m.get("max_range", c.max_range, 0.01, 65.0);
  if (c.max_range <= c.min_range) m.fail("max_range", "must exceed min_range");
}

}  // namespace

void load(runtime::ConfigMap& m, SimulatorConfig& c) {
  // At most 10 ms: at 1.5 m/s the body then moves 1.5 cm a step and cannot skip through a 10 cm wall.
  m.get("step_us", c.step_us, int64_t{10}, int64_t{10000});
  int64_t seed = static_cast<int64_t>(c.seed);
  m.get("seed", seed);
  c.seed = static_cast<uint64_t>(seed);
  m.get("camera_rate_hz", c.camera_rate_hz, 0.1, 1000.0);
  m.get("odometry_rate_hz", c.odometry_rate_hz, 0.1, 10000.0);
  m.get("command_timeout_us", c.command_timeout_us, int64_t{0}, int64_t{3600000000});
  m.get("cylinder_segments", c.cylinder_segments, 3, 1024);
  auto cam = m.child("camera");
  load_camera(cam, c.camera);
  auto veh = m.child("vehicle");
  load(veh, c.vehicle);
  auto imu = m.child("imu");
  load(imu, c.imu);
  auto dn = m.child("depth_noise");
  load(dn, c.depth_noise);
  auto det = m.child("detection_noise");
  load(det, c.detection_noise);
}

Simulator::Simulator(World world, const SimulatorConfig& config)
    : world_(std::make_unique<World>(std::move(world))),
      config_(config),
      imu_(config.imu, core::mix_seed(config.seed, kImuStream)) {
  vehicle_ = std::make_unique<Quadrotor>(*world_, config_.vehicle);
  RasterizerOptions ro;
  ro.mesh.cylinder_segments = config_.cylinder_segments;
  rasterizer_ = std::make_unique<Rasterizer>(*world_, ro);
}

CommandResult Simulator::command(const ControlCommand& cmd) {
  CommandResult r = vehicle_->command(cmd);
  if (r.accepted) {
    last_command_us_ = time_us_;
    timed_out_ = false;
  }
  return r;
}

int64_t Simulator::due_time(int64_t k, double rate_hz) const {
  return static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e6 / rate_hz));
}

StepResult Simulator::step() {
  StepResult r;
  time_us_ += config_.step_us;
  r.utime = time_us_;
  if (config_.command_timeout_us > 0 && !timed_out_ &&
      vehicle_->active_command().mode != ControlCommand::kHold &&
      time_us_ - last_command_us_ > config_.command_timeout_us) {
    vehicle_->hold();
    timed_out_ = true;
    ++timeouts_;
    r.command_timed_out = true;
  }
  const StepReport rep = vehicle_->step(config_.step_us * 1e-6);
  if (rep.collision_start) {
    r.collision = CollisionEvent{time_us_, vehicle_->state().position, rep.solid, vehicle_->collisions()};
  }
  // One sample per step at most: a step longer than a sensor's period decimates it.
  auto due = [&](int64_t& count, double rate) {
    if (time_us_ < due_time(count + 1, rate)) return false;
    while (time_us_ >= due_time(count + 1, rate)) ++count;
    return true;
  };
  if (due(imu_count_, config_.imu.rate_hz)) r.imu = imu_.sample(time_us_, vehicle_->state());
  if (due(odom_count_, config_.odometry_rate_hz)) r.odometry = odometry();
  r.camera_due = due(camera_count_, config_.camera_rate_hz);
  return r;
}

OdometrySample Simulator::odometry() const {
  const VehicleState& s = vehicle_->state();
  OdometrySample o;
  o.utime = time_us_;
  o.position = s.position;
  o.orientation = s.orientation();
  o.velocity = s.velocity;
  o.angular_velocity = {0, 0, s.yaw_rate};
  return o;
}

void Simulator::render_camera(CameraFrame& out, unsigned channels) {
  rasterizer_->render(config_.camera, vehicle_->state().camera_pose(), channels, out);
  out.utime = time_us_;
  out.frame_id = camera_count_;
  const uint64_t id = static_cast<uint64_t>(camera_count_);
  if (channels & kRenderDepth) {
    apply_depth_noise(out.depth, config_.depth_noise,
                      core::mix_seed(core::mix_seed(config_.seed, kDepthStream), id));
  }
  if (channels & kRenderLabels) {
    apply_detection_noise(out, config_.detection_noise,
                          core::mix_seed(core::mix_seed(config_.seed, kDetectionStream), id));
  }
}

namespace {
constexpr uint32_t kStateVersion = 1;
}  // namespace

std::vector<uint8_t> Simulator::save_state() const {
  std::vector<uint8_t> out;
  core::ByteWriter w(out);
  w.u32(kStateVersion);
  // What the state is only valid for: the same world, seed and step.
  w.str(world_->name);
  w.u64(config_.seed);
  w.i64(config_.step_us);
  w.i64(time_us_);
  w.i64(camera_count_);
  w.i64(imu_count_);
  w.i64(odom_count_);
  w.i64(last_command_us_);
  w.u8(timed_out_ ? 1 : 0);
  w.i64(timeouts_);
  vehicle_->save(w);
  imu_.save(w);
  return out;
}

void Simulator::restore_state(const std::vector<uint8_t>& bytes) {
  core::ByteReader r(bytes.data(), bytes.size());
  try {
    if (r.u32() != kStateVersion) throw std::runtime_error("simulator state of another version");
    const std::string world = r.str();
    const uint64_t seed = r.u64();
    const int64_t step = r.i64();
    if (world != world_->name || seed != config_.seed || step != config_.step_us) {
      throw std::runtime_error("simulator state of another run (world '" + world + "', seed " +
                               std::to_string(seed) + ", step " + std::to_string(step) + " us)");
    }
    const int64_t time_us = r.i64();
    const int64_t camera = r.i64(), imu = r.i64(), odom = r.i64(), last_command = r.i64();
    const bool timed_out = r.u8() != 0;
    const int64_t timeouts = r.i64();
    // Into copies first, so a short file leaves this simulator as it was.
    Quadrotor vehicle(*world_, config_.vehicle);
    vehicle.restore(r);
    ImuModel imu_model = imu_;
    imu_model.restore(r);
    if (r.remaining() != 0) throw std::runtime_error("simulator state has trailing bytes");
    vehicle_ = std::make_unique<Quadrotor>(std::move(vehicle));
    time_us_ = time_us;
    camera_count_ = camera;
    imu_count_ = imu;
    odom_count_ = odom;
    last_command_us_ = last_command;
    timed_out_ = timed_out;
    timeouts_ = timeouts;
    imu_ = imu_model;
  } catch (const std::out_of_range&) {
    throw std::runtime_error("simulator state is truncated");
  }
}

}  // namespace semx::simulator
