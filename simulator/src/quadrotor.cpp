#include "semx/simulator/quadrotor.hpp"

#include <cmath>

#include "semx/core/angles.hpp"
#include "semx/runtime/pinhole_camera.hpp"
#include "semx/simulator/collision.hpp"

namespace semx::simulator {
namespace {

Eigen::Vector3d limit_velocity(Eigen::Vector3d v, const VehicleConfig& c) {
  const double xy = v.head<2>().norm();
  if (xy > c.max_speed_xy) v.head<2>() *= c.max_speed_xy / xy;
  v.z() = std::clamp(v.z(), -c.max_speed_z, c.max_speed_z);
  return v;
}

}  // namespace

void load(runtime::ConfigMap& m, VehicleConfig& c) {
  m.get("velocity_time_constant", c.velocity_time_constant, 0.01, 10.0);
  m.get("max_speed_xy", c.max_speed_xy, 0.01, 20.0);
  m.get("max_speed_z", c.max_speed_z, 0.01, 20.0);
  m.get("max_acceleration", c.max_acceleration, 0.01, 50.0);
  m.get("max_yaw_rate", c.max_yaw_rate, 0.01, 20.0);
  m.get("yaw_time_constant", c.yaw_time_constant, 0.001, 10.0);
  m.get("yaw_gain", c.yaw_gain, 0.01, 100.0);
  m.get("hold_gain", c.hold_gain, 0.01, 100.0);
  m.get("command_tolerance", c.command_tolerance, 1.0, 100.0);
  if (m.has("body_size")) {
    std::vector<double> v;
    m.get("body_size", v);
    if (v.size() != 3 || v[0] <= 0 || v[1] <= 0 || v[2] <= 0)
      m.fail("body_size", "expected 3 positive numbers");
    c.body_size = {v[0], v[1], v[2]};
  }
}

ControlCommand ControlCommand::velocity(const Eigen::Vector3d& v, double yaw_rate) {
  ControlCommand c;
  c.mode = kVelocity;
  c.setpoint = v;
  c.yaw_mode = kYawRate;
  c.yaw_rate = yaw_rate;
  return c;
}

ControlCommand ControlCommand::velocity_yaw(const Eigen::Vector3d& v, double yaw) {
  ControlCommand c = velocity(v);
  c.yaw_mode = kYawAngle;
  c.yaw = yaw;
  return c;
}

ControlCommand ControlCommand::acceleration(const Eigen::Vector3d& a, double yaw_rate) {
  ControlCommand c = velocity(a, yaw_rate);
  c.mode = kAcceleration;
  return c;
}

ControlCommand ControlCommand::hold() { return ControlCommand(); }

Eigen::Isometry3d VehicleState::body_pose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = position;
  return T;
}

Eigen::Isometry3d VehicleState::camera_pose() const {
  Eigen::Isometry3d T = body_pose();
  T.linear() = T.linear() * runtime::optical_in_body();
  return T;
}

Quadrotor::Quadrotor(const World& world, const VehicleConfig& config) : world_(world), config_(config) {
  for (const auto& s : world.solids) solid_bounds_.push_back(s.bounds());
  state_.position = world.start.position;
  state_.yaw = core::wrap_angle(world.start.yaw);
  hold_position_ = state_.position;
}

void Quadrotor::set_state(const VehicleState& s) {
  state_ = s;
  hold_position_ = s.position;
  in_contact_ = false;
  contact_solid_ = -1;
}

int Quadrotor::body_hit(const Eigen::Vector3d& position, double yaw) const {
  const YawBox body{position, config_.body_size, yaw};
  const Aabb bb = body.bounds();
  for (size_t i = 0; i < world_.solids.size(); ++i) {
    if (bb.overlaps(solid_bounds_[i]) && overlaps(body, world_.solids[i])) return static_cast<int>(i);
  }
  return -1;
}

void Quadrotor::hold() {
  cmd_ = ControlCommand::hold();
  hold_position_ = state_.position;
}

CommandResult Quadrotor::command(const ControlCommand& cmd) {
  CommandResult r;
  const double tol = config_.command_tolerance;
  if (cmd.mode != ControlCommand::kHold && cmd.mode != ControlCommand::kVelocity &&
      cmd.mode != ControlCommand::kAcceleration) {
    r = {false, "unknown mode " + std::to_string(cmd.mode)};
  } else if (cmd.yaw_mode != ControlCommand::kYawAngle && cmd.yaw_mode != ControlCommand::kYawRate) {
    r = {false, "unknown yaw mode " + std::to_string(cmd.yaw_mode)};
  } else if (!cmd.setpoint.allFinite() || !std::isfinite(cmd.yaw) || !std::isfinite(cmd.yaw_rate)) {
    r = {false, "non-finite value"};
  } else if (cmd.mode == ControlCommand::kVelocity &&
             (cmd.setpoint.head<2>().norm() > tol * config_.max_speed_xy ||
              std::abs(cmd.setpoint.z()) > tol * config_.max_speed_z)) {
    r = {false, "velocity setpoint beyond the limits"};
  } else if (cmd.mode == ControlCommand::kAcceleration &&
             cmd.setpoint.norm() > tol * config_.max_acceleration) {
    r = {false, "acceleration setpoint beyond the limit"};
  } else if (cmd.yaw_mode == ControlCommand::kYawRate &&
             std::abs(cmd.yaw_rate) > tol * config_.max_yaw_rate) {
    r = {false, "yaw rate beyond the limit"};
  }
  if (!r.accepted) {
    ++rejected_;
    hold();
    return r;
  }
  const bool was_hold = cmd_.mode == ControlCommand::kHold;
  cmd_ = cmd;
  if (cmd.mode == ControlCommand::kHold && !was_hold) hold_position_ = state_.position;
  return r;
}

StepReport Quadrotor::step(double dt) {
  StepReport report;
  if (!(dt > 0)) return report;
  const VehicleConfig& c = config_;
  const VehicleState prev = state_;

  Eigen::Vector3d accel;
  if (cmd_.mode == ControlCommand::kAcceleration) {
    accel = cmd_.setpoint;
  } else {
    const Eigen::Vector3d target = cmd_.mode == ControlCommand::kVelocity
                                       ? cmd_.setpoint
                                       : Eigen::Vector3d(c.hold_gain * (hold_position_ - prev.position));
    accel = (limit_velocity(target, c) - prev.velocity) / c.velocity_time_constant;
  }
  const double an = accel.norm();
  if (an > c.max_acceleration) accel *= c.max_acceleration / an;
  Eigen::Vector3d v = limit_velocity(prev.velocity + accel * dt, c);
  const Eigen::Vector3d p = prev.position + 0.5 * (prev.velocity + v) * dt;

  double rate_cmd = cmd_.yaw_mode == ControlCommand::kYawRate
                        ? cmd_.yaw_rate
                        : c.yaw_gain * core::wrap_angle(cmd_.yaw - prev.yaw);
  if (cmd_.mode == ControlCommand::kHold) rate_cmd = 0;
  rate_cmd = std::clamp(rate_cmd, -c.max_yaw_rate, c.max_yaw_rate);
  const double alpha = std::min(1.0, dt / c.yaw_time_constant);
  const double yaw_rate = prev.yaw_rate + alpha * (rate_cmd - prev.yaw_rate);
  const double yaw = core::wrap_angle(prev.yaw + 0.5 * (prev.yaw_rate + yaw_rate) * dt);

  const int hit = body_hit(p, yaw);
  const auto touch = [&] {
    report.blocked = true;
    report.solid = hit;
    report.collision_start = !in_contact_;
    if (!in_contact_) ++collisions_;
    ++blocked_steps_;
    in_contact_ = true;
    contact_solid_ = hit;
  };
  if (hit >= 0 && yaw != prev.yaw && body_hit(p, prev.yaw) < 0) {
    // The solid stops the turn, not a move away from it: a body touching a wall with a corner
    // could never leave when every step also turned that corner into the wall (the step was
    // refused whole and the velocity zeroed, so the next step was as small).
    touch();
    state_.position = p;
    state_.velocity = v;
    state_.acceleration = (v - prev.velocity) / dt;
    state_.yaw_rate = 0;
    return report;
  }
  if (hit >= 0) {
    // Stop at the last free pose instead of entering the solid.
    touch();
    state_.velocity.setZero();
    state_.yaw_rate = 0;
    state_.acceleration = -prev.velocity / dt;
    return report;
  }
  // A contact ends only once the body has backed off by a margin, so pushing on against a
  // solid (stop, creep, stop) counts as one collision.
  if (in_contact_) {
    const YawBox grown{p, config_.body_size + Eigen::Vector3d::Constant(2 * kContactMargin), yaw};
    in_contact_ = contact_solid_ >= 0 && overlaps(grown, world_.solids[contact_solid_]);
  }
  state_.position = p;
  state_.velocity = v;
  state_.acceleration = (v - prev.velocity) / dt;
  state_.yaw = yaw;
  state_.yaw_rate = yaw_rate;
  return report;
}

namespace {
void put(core::ByteWriter& w, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) w.f64(v[i]);
}
Eigen::Vector3d get_vec(core::ByteReader& r) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = r.f64();
  return v;
}
}  // namespace

void Quadrotor::save(core::ByteWriter& w) const {
  put(w, state_.position);
  put(w, state_.velocity);
  put(w, state_.acceleration);
  w.f64(state_.yaw);
  w.f64(state_.yaw_rate);
  w.i32(cmd_.mode);
  put(w, cmd_.setpoint);
  w.i32(cmd_.yaw_mode);
  w.f64(cmd_.yaw);
  w.f64(cmd_.yaw_rate);
  put(w, hold_position_);
  w.u8(in_contact_ ? 1 : 0);
  w.i32(contact_solid_);
  w.i64(collisions_);
  w.i64(blocked_steps_);
  w.i64(rejected_);
}

void Quadrotor::restore(core::ByteReader& r) {
  state_.position = get_vec(r);
  state_.velocity = get_vec(r);
  state_.acceleration = get_vec(r);
  state_.yaw = r.f64();
  state_.yaw_rate = r.f64();
  cmd_.mode = r.i32();
  cmd_.setpoint = get_vec(r);
  cmd_.yaw_mode = r.i32();
  cmd_.yaw = r.f64();
  cmd_.yaw_rate = r.f64();
  hold_position_ = get_vec(r);
  in_contact_ = r.u8() != 0;
  contact_solid_ = r.i32();
  collisions_ = r.i64();
  blocked_steps_ = r.i64();
  rejected_ = r.i64();
}

}  // namespace semx::simulator
