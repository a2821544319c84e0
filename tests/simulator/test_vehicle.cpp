#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "semx/simulator/collision.hpp"
#include "semx/simulator/imu.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "test_util.hpp"

namespace semx::simulator {
namespace {

constexpr double kDt = 0.001;

bool body_in_any_solid(const World& w, const VehicleState& s) {
  return first_solid_hit_by_body(w, s.position, s.yaw) >= 0;
}

TEST(Collision, BoxBoxAndBoxCylinderAreExact) {
  const YawBox body{{0, 0, 1}, {0.5, 0.5, 0.3}, 0.0};
  // Axis-aligned: touching is not overlapping, a hair closer is.
  EXPECT_FALSE(overlaps(body, Solid::box(SemanticClass::kWall, {0.5, 0, 1}, {0.5, 2, 2})));
  EXPECT_TRUE(overlaps(body, Solid::box(SemanticClass::kWall, {0.4999, 0, 1}, {0.5, 2, 2})));
  // Z separation.
  EXPECT_FALSE(overlaps(body, Solid::box(SemanticClass::kTable, {0, 0, 0.425}, {1, 1, 0.85})));
  EXPECT_TRUE(overlaps(body, Solid::box(SemanticClass::kTable, {0, 0, 0.43}, {1, 1, 0.85})));
  // A box yawed 45 deg: its corner reaches 0.5·√2 from its centre.
  const double reach = 0.25 * std::sqrt(2.0) + 0.25;
  EXPECT_FALSE(
      overlaps(body, Solid::box(SemanticClass::kCabinet, {reach + 1e-4, 0, 1}, {0.5, 0.5, 1}, M_PI / 4)));
  EXPECT_TRUE(
      overlaps(body, Solid::box(SemanticClass::kCabinet, {reach - 1e-4, 0, 1}, {0.5, 0.5, 1}, M_PI / 4)));
  // Rotated body against a rotated box, separated only along a diagonal axis.
  const YawBox rotated{{0, 0, 1}, {0.5, 0.5, 0.3}, M_PI / 4};
  const double touch = 0.5 * std::sqrt(2.0);  // the diamonds' faces meet at x = 0.5·√2
  EXPECT_FALSE(
      overlaps(rotated, Solid::box(SemanticClass::kCabinet, {touch + 1e-4, 0, 1}, {0.5, 0.5, 1}, M_PI / 4)));
  EXPECT_TRUE(
      overlaps(rotated, Solid::box(SemanticClass::kCabinet, {touch - 1e-4, 0, 1}, {0.5, 0.5, 1}, M_PI / 4)));
  EXPECT_TRUE(overlaps(rotated, YawBox{{touch - 1e-4, 0, 1.2}, {0.5, 0.5, 0.3}, M_PI / 4}));
  // Cylinder beside a face, and diagonal to a corner (where the box's AABB would overlap).
  EXPECT_FALSE(overlaps(body, Solid::cylinder(SemanticClass::kPlant, {0.25 + 0.3 + 1e-4, 0, 1}, 0.3, 2)));
  EXPECT_TRUE(overlaps(body, Solid::cylinder(SemanticClass::kPlant, {0.25 + 0.3 - 1e-4, 0, 1}, 0.3, 2)));
  const double diag = 0.3 / std::sqrt(2.0) + 0.25;
  EXPECT_FALSE(overlaps(body, Solid::cylinder(SemanticClass::kPlant, {diag + 1e-3, diag + 1e-3, 1}, 0.3, 2)));
  EXPECT_TRUE(overlaps(body, Solid::cylinder(SemanticClass::kPlant, {diag - 1e-3, diag - 1e-3, 1}, 0.3, 2)));
}

TEST(Quadrotor, FirstOrderVelocityResponse) {
  const World w = test::box_room(20, 20, 3);
  VehicleConfig c;
  Quadrotor q(w, c);
  // Small step: the acceleration limit never binds, so v(t) = v_cmd (1 - e^{-t/τ}).
  ASSERT_TRUE(q.command(ControlCommand::velocity({0.3, 0, 0})).accepted);
  for (int i = 0; i < static_cast<int>(c.velocity_time_constant / kDt); ++i) q.step(kDt);
  EXPECT_NEAR(q.state().velocity.x(), 0.3 * (1 - std::exp(-1.0)), 0.003);
  for (int i = 0; i < 3000; ++i) q.step(kDt);
  EXPECT_NEAR(q.state().velocity.x(), 0.3, 1e-3);
  EXPECT_NEAR(q.state().velocity.y(), 0.0, 1e-12);
}

TEST(Quadrotor, RespectsVelocityAccelerationAndYawRateLimits) {
  const World w = test::box_room(40, 40, 20);
  VehicleConfig c;
  Quadrotor q(w, c);
  const double s = c.max_speed_xy * c.command_tolerance;
  ASSERT_TRUE(q.command(ControlCommand::velocity({s * 0.8, s * 0.6, c.max_speed_z * c.command_tolerance},
                                                 c.max_yaw_rate))
                  .accepted);
  double max_v = 0, max_vz = 0, max_a = 0, max_r = 0;
  for (int i = 0; i < 4000; ++i) {
    q.step(kDt);
    max_v = std::max(max_v, q.state().velocity.head<2>().norm());
    max_vz = std::max(max_vz, std::abs(q.state().velocity.z()));
    max_a = std::max(max_a, q.state().acceleration.norm());
    max_r = std::max(max_r, std::abs(q.state().yaw_rate));
  }
  EXPECT_LE(max_v, c.max_speed_xy + 1e-9);
  EXPECT_NEAR(max_v, c.max_speed_xy, 1e-3);  // saturated, not rejected
  EXPECT_LE(max_vz, c.max_speed_z + 1e-9);
  EXPECT_LE(max_a, c.max_acceleration + 1e-9);
  EXPECT_LE(max_r, c.max_yaw_rate + 1e-9);
  EXPECT_EQ(q.rejected_commands(), 0);

  // Acceleration mode: the setpoint is the acceleration, within its limit.
  Quadrotor q2(w, c);
  ASSERT_TRUE(q2.command(ControlCommand::acceleration({1.0, 0, 0})).accepted);
  for (int i = 0; i < 500; ++i) q2.step(kDt);
  EXPECT_NEAR(q2.state().velocity.x(), 0.5, 1e-9);
  EXPECT_NEAR(q2.state().position.x() - w.start.position.x(), 0.125, 1e-6);
}

TEST(Quadrotor, YawAngleModeTurnsTheShortWay) {
  const World w = test::box_room(10, 10, 3);
  Quadrotor q(w, VehicleConfig{});
  VehicleState s = q.state();
  s.yaw = 3.0;
  q.set_state(s);
  ASSERT_TRUE(q.command(ControlCommand::velocity_yaw({0, 0, 0}, -3.0)).accepted);  // 0.28 rad through ±π
  q.step(kDt);
  q.step(kDt);
  EXPECT_GT(q.state().yaw_rate, 0);
  for (int i = 0; i < 5000; ++i) q.step(kDt);
  EXPECT_NEAR(std::remainder(q.state().yaw - (-3.0), 2 * M_PI), 0.0, 1e-3);
}

TEST(Quadrotor, RejectsNanAndOutOfRangeCommandsAndHolds) {
  const World w = test::box_room(20, 20, 3);
  VehicleConfig c;
  Quadrotor q(w, c);
  ASSERT_TRUE(q.command(ControlCommand::velocity({1.0, 0.5, 0})).accepted);
  for (int i = 0; i < 1500; ++i) q.step(kDt);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ControlCommand bad[] = {
      ControlCommand::velocity({nan, 0, 0}),
      ControlCommand::velocity({0, 0, 0}, std::numeric_limits<double>::infinity()),
      ControlCommand::velocity({10 * c.max_speed_xy, 0, 0}),
      ControlCommand::velocity({0, 0, -5 * c.max_speed_z}),
      ControlCommand::acceleration({0, 0, 100}),
      ControlCommand::velocity({0, 0, 0}, 10 * c.max_yaw_rate),
      [] {
        ControlCommand x;
        x.mode = 7;
        return x;
      }(),
      ControlCommand::velocity_yaw({0, 0, 0}, nan),
  };
  int64_t expected = 0;
  for (const auto& cmd : bad) {
    const CommandResult r = q.command(cmd);
    EXPECT_FALSE(r.accepted);
    EXPECT_FALSE(r.reason.empty());
    EXPECT_EQ(q.rejected_commands(), ++expected);
    EXPECT_EQ(q.active_command().mode, ControlCommand::kHold);
  }
  // Holding: the vehicle brakes and returns to where the first bad command found it.
  const Eigen::Vector3d hold_at = q.state().position;
  for (int i = 0; i < 8000; ++i) {
    q.step(kDt);
    ASSERT_TRUE(q.state().position.allFinite());
  }
  EXPECT_LT((q.state().position - hold_at).norm(), 0.01);
  EXPECT_LT(q.state().velocity.norm(), 0.01);
}

TEST(Quadrotor, CollisionStopsTheVehicleAndIsCountedOnce) {
  World w = test::box_room(6, 4, 3);
  w.start.position = {1, 2, 1.2};
  w.solids.push_back(Solid::cylinder(SemanticClass::kPlant, {3, 2, 1.0}, 0.3, 2.0));
  Quadrotor q(w, VehicleConfig{});
  ASSERT_TRUE(q.command(ControlCommand::velocity({1.0, 0, 0})).accepted);
  int starts = 0;
  for (int i = 0; i < 6000; ++i) {
    const StepReport r = q.step(kDt);
    starts += r.collision_start;
    if (r.blocked) {
      EXPECT_EQ(r.solid, static_cast<int>(w.solids.size()) - 1);
    }
    ASSERT_FALSE(body_in_any_solid(w, q.state())) << "step " << i;
  }
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(q.collisions(), 1);
  EXPECT_GT(q.blocked_steps(), 1000);
  EXPECT_LT(q.state().position.x(), 3 - 0.3 - 0.25);
  EXPECT_GT(q.state().position.x(), 3 - 0.3 - 0.25 - 0.01);  // stopped within one step of contact
  // Backing off clears the contact; coming back is a second collision.
  ASSERT_TRUE(q.command(ControlCommand::velocity({-0.5, 0, 0})).accepted);
  for (int i = 0; i < 1000; ++i) q.step(kDt);
  ASSERT_TRUE(q.command(ControlCommand::velocity({0.5, 0, 0})).accepted);
  for (int i = 0; i < 3000; ++i) q.step(kDt);
  EXPECT_EQ(q.collisions(), 2);
  // A yaw that would swing the body's corner into the plant is blocked too.
  ASSERT_TRUE(q.command(ControlCommand::velocity({0, 0, 0}, 1.0)).accepted);
  for (int i = 0; i < 2000; ++i) {
    q.step(kDt);
    ASSERT_FALSE(body_in_any_solid(w, q.state()));
  }
}

TEST(Quadrotor, ATurnIntoASolidDoesNotStopAMoveAwayFromIt) {
  // The body, turned 22.5°, touches a wall with a corner; the command moves it away while turning
  // that corner into the wall. The wall stops the turn, not the move: refusing the whole step (and
  // zeroing the velocity) had held a vehicle there for seconds (env3, fuel's latency tour, seed 1).
  World w = test::box_room(6, 4, 3);
  w.start.position = {1, 2, 1.2};
  w.start.yaw = M_PI / 8;
  w.solids.push_back(Solid::box(SemanticClass::kWall, {3, 2, 1.35}, {0.1, 3.8, 2.7}));
  Quadrotor q(w, VehicleConfig{});
  ASSERT_TRUE(q.command(ControlCommand::velocity_yaw({0.5, 0, 0}, M_PI / 8)).accepted);
  for (int i = 0; i < 5000; ++i) q.step(kDt);
  ASSERT_EQ(q.collisions(), 1);
  const VehicleState touching = q.state();
  // A corner turned 22.5° reaches 0.25 (cos 22.5° + sin 22.5°) = 0.327 m.
  ASSERT_NEAR(touching.position.x(), 2.95 - 0.327, 0.02);
  // Away along -x while the heading turns to 45° (which swings the corner further toward +x).
  ASSERT_TRUE(q.command(ControlCommand::velocity_yaw({-0.3, 0, 0}, M_PI / 4)).accepted);
  for (int i = 0; i < 1000; ++i) {
    q.step(kDt);
    ASSERT_FALSE(body_in_any_solid(w, q.state())) << "step " << i;
  }
  EXPECT_LT(q.state().position.x(), touching.position.x() - 0.1) << "it moved away";
  EXPECT_EQ(q.collisions(), 1) << "one contact";
  // Far enough, the turn is free again.
  for (int i = 0; i < 3000; ++i) q.step(kDt);
  EXPECT_NEAR(q.state().yaw, M_PI / 4, 0.05);
}

TEST(Imu, NoiseDensityAndGravity) {
  ImuConfig c;
  ImuModel imu(c, 3);
  VehicleState s;
  s.yaw = 0.7;
  s.acceleration = {1.0, 0, 0};
  const int n = 20000;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const ImuSample m = imu.sample(i * 5000, s);
    sum += m.linear_acceleration;
    sq += (m.linear_acceleration - specific_force(s, c.gravity)).cwiseAbs2();
  }
  const Eigen::Vector3d mean = sum / n;
  // World acceleration (1, 0, 0) seen from a body yawed 0.7 rad, plus gravity's reaction.
  EXPECT_NEAR(mean.x(), std::cos(0.7), 0.01);
  EXPECT_NEAR(mean.y(), -std::sin(0.7), 0.01);
  EXPECT_NEAR(mean.z(), c.gravity, 0.01);
  const double sigma = c.accel_noise_density * std::sqrt(c.rate_hz);  // 0.24 m/s²
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::sqrt(sq[k] / n), sigma, 0.03 * sigma);
  ImuModel a(c, 3), b(c, 3);
  EXPECT_EQ(a.sample(0, s).angular_velocity, b.sample(0, s).angular_velocity);
}

}  // namespace
}  // namespace semx::simulator
