// A closed loop for controller tests: the Controller fed by a point-mass vehicle that responds to
// CONTROL_CMD like the simulator's (first-order velocity lag τ = 0.3 s, acceleration ≤ 3 m/s²,
// HOLD returns to where it started holding, yaw angle loop with gain 2/s), stepped at 100 Hz of
// message time, the command of one tick applied over the next.
#pragma once

#include <memory>

#include "semx/controller/controller.hpp"
#include "semx/core/angles.hpp"

namespace semx::controller::test {

struct PointMass {
  double tau = 0.3, max_acceleration = 3.0, hold_gain = 1.5, yaw_gain = 2.0, max_yaw_rate = 1.5;
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  Eigen::Vector3d hold_position = Eigen::Vector3d::Zero();
  bool holding = true;

  void apply(const Command& c, double dt) {
    const bool hold = c.mode == Command::Mode::kHold;
    if (hold && !holding) hold_position = position;
    holding = hold;
    const Eigen::Vector3d target =
        hold ? Eigen::Vector3d(hold_gain * (hold_position - position)) : c.velocity;
    Eigen::Vector3d a = (target - velocity) / tau;
    if (a.norm() > max_acceleration) a *= max_acceleration / a.norm();
    const Eigen::Vector3d v = velocity + a * dt;
    position += 0.5 * (velocity + v) * dt;
    velocity = v;
    if (!hold)
      yaw = core::wrap_angle(
          yaw + std::clamp(yaw_gain * core::wrap_angle(c.yaw - yaw), -max_yaw_rate, max_yaw_rate) * dt);
  }
};

struct Loop {
  explicit Loop(const ControllerConfig& cfg, std::shared_ptr<const DistanceField> field)
      : controller(cfg), field(std::move(field)) {}

  Controller controller;
  std::shared_ptr<const DistanceField> field;
  PointMass vehicle;
  int64_t now = 1'000'000;  // µs
  bool send_odometry = true, send_esdf = true;
  int esdf_every = 3;  // ticks (≈ 30 Hz)
  int tick = 0;
  StepOutput last;

  VehicleState odometry() const {
    VehicleState s;
    s.utime = now;
    s.position = vehicle.position;
    s.velocity = vehicle.velocity;
    s.yaw = vehicle.yaw;
    return s;
  }

  void send_path(std::vector<Eigen::Vector3d> waypoints, std::vector<double> yaws, int64_t plan_id,
                 double max_speed = 0.0) {
    Path p;
    p.utime = now;
    p.plan_id = plan_id;
    p.waypoints = std::move(waypoints);
    p.yaws = std::move(yaws);
    p.max_speed = max_speed;
    controller.on_path(std::move(p));
  }

  // One 10 ms tick: inputs stamped now, a control step, the vehicle moves.
  const StepOutput& step() {
    if (send_odometry) controller.on_odometry(odometry());
    if (send_esdf && tick % esdf_every == 0) controller.on_esdf(field, now);
    last = controller.step(now);
    vehicle.apply(last.command, 0.01);
    now += 10'000;
    ++tick;
    return last;
  }

  void run(double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 100 + 0.5); ++i) step();
  }
  // Steps while the controller is TRACKING; returns the largest tracking error seen.
  double track_to_end() {
    double worst = 0;
    while (controller.status().state == ControllerState::kTracking) {
      step();
      worst = std::max(worst, last.status.tracking_error);
    }
    return worst;
  }
  // Steps until `pred` or `seconds` pass; returns whether pred held.
  template <class F>
  bool run_until(F pred, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 100 + 0.5); ++i) {
      step();
      if (pred()) return true;
    }
    return false;
  }
};

}  // namespace semx::controller::test
