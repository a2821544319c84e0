// IMU: specific force and angular rate in the (level, yawed) body frame with white noise of the
// paper's densities and optional bias random walks.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semx/core/random.hpp"
#include "semx/runtime/config.hpp"
#include "semx/simulator/quadrotor.hpp"

namespace semx::simulator {

struct ImuConfig {
  double rate_hz = 200.0;
  double accel_noise_density = 1.7e-2;  // m/s²/√Hz
  double gyro_noise_density = 1.7e-2;   // rad/s/√Hz
  double accel_bias_random_walk = 0.0;  // m/s³/√Hz
  double gyro_bias_random_walk = 0.0;   // rad/s²/√Hz
  double gravity = 9.81;                // m/s²
};
void load(runtime::ConfigMap& m, ImuConfig& c);

struct ImuSample {
  int64_t utime = 0;
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // specific force, body, m/s²
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // body, rad/s
};

class ImuModel {
 public:
  ImuModel(const ImuConfig& config, uint64_t seed);
  // A sample of the state; white noise has σ = density · √rate per sample.
  ImuSample sample(int64_t utime, const VehicleState& state);
  // The generator and the biases, so a restored model draws what this one would have.
  void save(core::ByteWriter& w) const;
  void restore(core::ByteReader& r);

 private:
  ImuConfig config_;
  core::XoshiroRng rng_;
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero(), gyro_bias_ = Eigen::Vector3d::Zero();
};

// Ideal specific force of a level body: R_z(yaw)ᵀ (a + g ẑ).
Eigen::Vector3d specific_force(const VehicleState& state, double gravity);

}  // namespace semx::simulator
