#include "semx/simulator/imu.hpp"

#include <cmath>

namespace semx::simulator {

void load(runtime::ConfigMap& m, ImuConfig& c) {
  m.get("rate_hz", c.rate_hz, 1.0, 10000.0);
  m.get("accel_noise_density", c.accel_noise_density, 0.0, 10.0);
  m.get("gyro_noise_density", c.gyro_noise_density, 0.0, 10.0);
  m.get("accel_bias_random_walk", c.accel_bias_random_walk, 0.0, 10.0);
  m.get("gyro_bias_random_walk", c.gyro_bias_random_walk, 0.0, 10.0);
  m.get("gravity", c.gravity, 0.0, 100.0);
}

ImuModel::ImuModel(const ImuConfig& config, uint64_t seed) : config_(config), rng_(seed) {}

Eigen::Vector3d specific_force(const VehicleState& state, double gravity) {
  const Eigen::Vector3d f = state.acceleration + Eigen::Vector3d(0, 0, gravity);
  const double c = std::cos(state.yaw), s = std::sin(state.yaw);
  return {c * f.x() + s * f.y(), -s * f.x() + c * f.y(), f.z()};
}

ImuSample ImuModel::sample(int64_t utime, const VehicleState& state) {
  const double dt = 1.0 / config_.rate_hz;
  const double sa = config_.accel_noise_density / std::sqrt(dt);
  const double sg = config_.gyro_noise_density / std::sqrt(dt);
  auto noise = [this](double sigma) {
    Eigen::Vector3d n;
    for (int k = 0; k < 3; ++k) n[k] = sigma * rng_.normal();
    return n;
  };
  accel_bias_ += noise(config_.accel_bias_random_walk * std::sqrt(dt));
  gyro_bias_ += noise(config_.gyro_bias_random_walk * std::sqrt(dt));
  ImuSample s;
  s.utime = utime;
  s.linear_acceleration = specific_force(state, config_.gravity) + accel_bias_ + noise(sa);
  s.angular_velocity = Eigen::Vector3d(0, 0, state.yaw_rate) + gyro_bias_ + noise(sg);
  return s;
}

void ImuModel::save(core::ByteWriter& w) const {
  rng_.save(w);
  for (int i = 0; i < 3; ++i) w.f64(accel_bias_[i]);
  for (int i = 0; i < 3; ++i) w.f64(gyro_bias_[i]);
}

void ImuModel::restore(core::ByteReader& r) {
  rng_.restore(r);
  for (int i = 0; i < 3; ++i) accel_bias_[i] = r.f64();
  for (int i = 0; i < 3; ++i) gyro_bias_[i] = r.f64();
}

}  // namespace semx::simulator
