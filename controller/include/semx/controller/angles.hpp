// Heading helpers: yaws inside the controller are unwrapped (continuous) so splines through
// them never jump by 2π; only commands and comparisons wrap them.
#pragma once

#include <cmath>

namespace semx::controller {

// Angle wrapped to (-π, π].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

// The angle equal to `target` modulo 2π that is closest to `reference` (the shortest turn).
inline double unwrap_near(double target, double reference) {
  return reference + wrap_angle(target - reference);
}

// Yaw of a world-from-body unit quaternion (w, x, y, z), z up.
inline double yaw_of_quaternion(double w, double x, double y, double z) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

}  // namespace semx::controller
