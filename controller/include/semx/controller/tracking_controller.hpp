// The trajectory follower's control law, for a vehicle that takes world velocity setpoints and
// responds to them with a first-order lag τ (v̇ = (v_cmd - v)/τ, as the simulator does):
//
//   v_cmd = v_ref + τ_ff·a_ref + k_p·(p_ref - p) + k_v·(v_ref - v),   |v_cmd| <= max_command_speed, |v_cmd.z| <= max_command_speed_z
//
// With τ_ff = τ the feed-forward makes the vehicle's velocity follow v_ref exactly, and the error
// e = p_ref - p obeys τ·ë + (1 + k_v)·ė + k_p·e = 0: stable for any k_p > 0, k_v > -1, and with the
// defaults (τ = 0.3 s, k_p = 2, k_v = 0.5) damped at ζ ≈ 1. The heading leads the reference by
// yaw_feedforward·ψ̇_ref to cancel the lag of a yaw-angle loop (rate = gain·error, lag = 1/gain).
#pragma once

#include "semx/controller/command.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/controller/vehicle_state.hpp"

namespace semx::controller {

class TrackingController {
 public:
  explicit TrackingController(const TrackingConfig& config) : config_(config) {}

  Command track(const TrajectoryPoint& reference, const VehicleState& vehicle) const;
  // Hold a point by feedback alone (the end of a finished trajectory).
  Command hold_at(const Eigen::Vector3d& position, double yaw, const VehicleState& vehicle) const;
  // Hover where the vehicle is: the HOLD mode (braking, stale inputs, nothing to fly).
  static Command hover(double yaw);

 private:
  Eigen::Vector3d limit(const Eigen::Vector3d& v) const;
  TrackingConfig config_;
};

}  // namespace semx::controller
