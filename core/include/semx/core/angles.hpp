// Yaw arithmetic. Yaws are wrapped only where they are compared or sent; a module that needs a
// continuous heading (the controller's splines) keeps it unwrapped and uses unwrap_near.
#pragma once

#include <cmath>

namespace semx::core {

inline constexpr double kPi = 3.14159265358979323846;

// Angle in (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

// |smallest rotation| from a to b, in [0, pi].
inline double yaw_distance(double a, double b) { return std::abs(wrap_angle(b - a)); }

// The angle equal to `target` modulo 2 pi that is closest to `reference` (the shortest turn).
inline double unwrap_near(double target, double reference) {
  return reference + wrap_angle(target - reference);
}

// Yaw of a world-from-body unit quaternion (w, x, y, z), z up.
inline double yaw_of_quaternion(double w, double x, double y, double z) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

}  // namespace semx::core
