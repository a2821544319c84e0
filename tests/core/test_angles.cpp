#include <gtest/gtest.h>

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::core {
namespace {

TEST(Angles, WrapIsInTheHalfOpenInterval) {
  for (double a = -20.0; a <= 20.0; a += 0.01) {
    const double w = wrap_angle(a);
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    EXPECT_NEAR(std::remainder(a - w, 2 * kPi), 0.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(3 * kPi), kPi);
}

TEST(Angles, YawDistanceIsTheShorterTurn) {
  EXPECT_NEAR(yaw_distance(0.1, -0.1), 0.2, 1e-12);
  EXPECT_NEAR(yaw_distance(kPi - 0.1, -kPi + 0.1), 0.2, 1e-12);
  EXPECT_NEAR(yaw_distance(0.0, kPi), kPi, 1e-12);
}

TEST(Angles, UnwrapNearIsTheEquivalentAngleClosestToTheReference) {
  EXPECT_NEAR(unwrap_near(-kPi + 0.1, 10 * kPi - 0.1), 11 * kPi + 0.1 - 2 * kPi + 0.0 - kPi + kPi, 1e-9);
  for (double ref = -10; ref < 10; ref += 0.37) {
    const double u = unwrap_near(1.0, ref);
    EXPECT_LE(std::abs(u - ref), kPi + 1e-12);
    EXPECT_NEAR(wrap_angle(u - 1.0), 0.0, 1e-9);
  }
}

TEST(Angles, YawOfAQuaternionAboutZ) {
  for (double yaw : {-3.0, -1.0, 0.0, 0.5, 3.1}) {
    EXPECT_NEAR(yaw_of_quaternion(std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)), yaw, 1e-12);
  }
}

}  // namespace
}  // namespace semx::core
