// The vehicle as odometry reports it (ODOMETRY as plain data).
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace semx::controller {

struct VehicleState {
  int64_t utime = 0;  // message time of the measurement, µs
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // world frame
  double yaw = 0.0;                                    // rad
};

}  // namespace semx::controller
