// Yaw arithmetic shared by the gain, the cost and the paths.
#pragma once

#include <cmath>

namespace semx::planner {

inline constexpr double kPi = 3.14159265358979323846;

// Angle in (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}
// |smallest rotation| from a to b, in [0, pi].
inline double yaw_distance(double a, double b) { return std::abs(wrap_angle(b - a)); }

}  // namespace semx::planner
