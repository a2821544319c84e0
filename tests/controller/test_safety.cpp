// Safety: the dense clearance check, braking on a predicted collision, stopping on stale
// inputs, and rejecting bad paths, through the Controller's state machine.
#include <gtest/gtest.h>

#include "fields.hpp"
#include "semx/controller/clearance.hpp"
#include "semx/fixtures/synthetic_scene.hpp"
#include "vehicle_sim.hpp"

using namespace semx::controller;
using namespace semx::controller::test;

namespace {

std::shared_ptr<GridDistanceField> boxes_field(const std::vector<Box>& boxes) {
  return std::make_shared<GridDistanceField>(
      rasterize_boxes(boxes, Eigen::Vector3d(-2, -5, 0), 0.1, 160, 100, 30, 2.0, OutsideWindow::kFree));
}

Trajectory straight(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double seconds) {
  PositionSpline::Points q;
  const int n = 20;
  q.push_back(a);
  for (int i = 0; i <= n; ++i) q.push_back(a + (b - a) * (static_cast<double>(i) / n));
  q.push_back(b);
  Trajectory t;
  t.position = PositionSpline(q, seconds / (n + 1));
  return t;
}

}  // namespace

TEST(Clearance, FindsAThinObstacleBetweenAnyTwoCoarseSamples) {
  // A 4 cm slab across a 10 m line: a coarse check could step over it, the dense one cannot.
  const auto field = boxes_field({{Eigen::Vector3d(5.0, -5, 0), Eigen::Vector3d(5.04, 5, 3)}});
  const Trajectory t = straight({0, 0, 1}, {10, 0, 1}, 10.0);
  ClearanceRule rule;
  const ClearanceReport r = check_clearance(t, *field, 0, t.duration(), rule);
  EXPECT_FALSE(r.ok);
  EXPECT_NEAR(r.violation_point.x(), 5.0 - rule.bound, 0.05);
  // The part before it is fine, and was sampled at least every `spacing`.
  const ClearanceReport before = check_clearance(t, *field, 0, 4.0, rule);
  EXPECT_TRUE(before.ok);
  EXPECT_GE(before.samples, 4.0 / rule.spacing);
}

TEST(Clearance, PadsTheBoundBetweenSamples) {
  // A field that is exactly the bound on the line still fails: between samples it could dip.
  ClearanceRule rule;
  FreeField at_bound(rule.bound);
  const Trajectory t = straight({0, 0, 1}, {1, 0, 1}, 1.0);
  EXPECT_TRUE(check_clearance(t, at_bound, 0, 1, rule).ok);  // a constant field cannot dip
  TubeField tube({{0, 0, 1}, {1, 0, 1}}, rule.bound);        // slope 1: it could
  EXPECT_FALSE(check_clearance(t, tube, 0, 1, rule).ok);
  TubeField wider({{0, 0, 1}, {1, 0, 1}}, rule.bound + 0.5 * rule.spacing + 1e-9);
  EXPECT_TRUE(check_clearance(t, wider, 0, 1, rule).ok);
}

TEST(Clearance, TheTurnedBodyReachesFartherTowardAWallsEnd) {
  // Passing a post (a wall's end seen from above) 0.34 m to the side: above the 0.32 m bound. Faced
  // square to it the box reaches 0.25 m; turned by 45° its corner reaches 0.354 m, into the post.
  EXPECT_NEAR(footprint_reach({0, 1, 0}, 0.0, 0.25, 0.15), 0.25, 1e-12);
  EXPECT_NEAR(footprint_reach({0, 1, 0}, M_PI / 4, 0.25, 0.15), 0.25 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(footprint_reach({0, 0, -1}, 0.3, 0.25, 0.15), 0.15, 1e-12);
  const PostField post(Eigen::Vector2d(2.0, 0.34));
  const auto with_yaw = [](double yaw) {
    Trajectory t = straight({0, 0, 1}, {4, 0, 1}, 4.0);
    t.yaw = YawSpline(YawSpline::Points(t.position.control_points().size(), YawSpline::Point(yaw)),
                      t.position.knot_interval());
    return t;
  };
  ClearanceRule rule;
  rule.bound = 0.32;
  rule.hard_bound = 0.25;
  EXPECT_TRUE(check_clearance(with_yaw(M_PI / 4), post, 0, 4, rule).ok) << "the bound alone";
  rule.footprint_half_xy = 0.25;
  rule.footprint_half_z = 0.15;
  rule.footprint_margin = 0.0;
  EXPECT_TRUE(check_clearance(with_yaw(0.0), post, 0, 4, rule).ok) << "a face toward the post";
  const ClearanceReport turned = check_clearance(with_yaw(M_PI / 4), post, 0, 4, rule);
  EXPECT_FALSE(turned.ok);
  EXPECT_TRUE(turned.footprint);
  EXPECT_NEAR(turned.violation_point.x(), 2.0, 0.15) << "where the corner meets the post";
}

TEST(Clearance, AStartWithinTheTurnedBodysReachMayMoveOutOfItButNotDeeper) {
  // The vehicle already stands turned by 45° at 0.345 m from a post, within its corner's 0.354 m
  // reach (env3, 35 samples, seed 3 stood so in a doorway for 550 s, every trajectory rejected at
  // t = 0). Leaving must pass; going 2 cm nearer must not.
  const PostField post(Eigen::Vector2d(2.0, 0.345));
  const auto turned = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    Trajectory t = straight(a, b, 2.0);
    t.yaw = YawSpline(YawSpline::Points(t.position.control_points().size(), YawSpline::Point(M_PI / 4)),
                      t.position.knot_interval());
    return t;
  };
  ClearanceRule rule;
  rule.bound = 0.30;
  rule.hard_bound = 0.25;
  rule.footprint_half_xy = 0.25;
  rule.footprint_half_z = 0.15;
  const Trajectory leaving = turned({2, 0, 1}, {2, -1, 1});
  EXPECT_TRUE(check_clearance(leaving, post, 0, leaving.duration(), rule).ok);
  const Trajectory along = turned({2, 0, 1}, {4, 0, 1});
  EXPECT_TRUE(check_clearance(along, post, 0, along.duration(), rule).ok);
  const Trajectory nearer = turned({2, 0, 1}, {2, 0.02, 1});
  const ClearanceReport r = check_clearance(nearer, post, 0, nearer.duration(), rule);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.footprint);
  rule.allow_escape = false;
  EXPECT_FALSE(check_clearance(leaving, post, 0, leaving.duration(), rule).ok) << "no escape allowed";
  // Once out of the reach, the full reach applies again: back past the post from farther away.
  const Trajectory back = turned({2, -0.3, 1}, {2, 0.02, 1});
  rule.allow_escape = true;
  EXPECT_FALSE(check_clearance(back, post, 0, back.duration(), rule).ok);
}

TEST(Clearance, AStartTouchingAWallMayLeaveOnlyMovingAway) {
  // A wall at x >= 2.2, the vehicle 0.2 m from it: below the hard bound (0.25 m), its body in
  // contact. It may leave when its distance rises by contact_rise per metre of arc until the hard
  // bound; sliding along the wall, or with contact_rise 0, it may not.
  const auto field = boxes_field({{Eigen::Vector3d(2.2, -5, 0), Eigen::Vector3d(3.0, 5, 3)}});
  ClearanceRule rule;
  rule.bound = 0.32;
  rule.hard_bound = 0.25;
  const Eigen::Vector3d start(2.0, 0, 1);
  ASSERT_LT(field->distance(start), rule.hard_bound);
  const Trajectory away = straight(start, {0.5, 0, 1}, 3.0);
  EXPECT_TRUE(check_clearance(away, *field, 0, away.duration(), rule).ok);
  const Trajectory slanted = straight(start, {0.8, -1.2, 1}, 3.0);  // 45° off the wall
  EXPECT_TRUE(check_clearance(slanted, *field, 0, slanted.duration(), rule).ok);
  const Trajectory along = straight(start, {2.0, -2, 1}, 3.0);
  const ClearanceReport r = check_clearance(along, *field, 0, along.duration(), rule);
  EXPECT_FALSE(r.ok);
  const Trajectory grazing = straight(start, {1.8, -2, 1}, 3.0);  // 6° off the wall
  EXPECT_FALSE(check_clearance(grazing, *field, 0, grazing.duration(), rule).ok);
  rule.contact_rise = 0.0;
  EXPECT_FALSE(check_clearance(away, *field, 0, away.duration(), rule).ok);
  rule.contact_rise = 0.5;
  rule.allow_escape = false;
  EXPECT_FALSE(check_clearance(away, *field, 0, away.duration(), rule).ok);
}

TEST(Safety, AVehicleTouchingAWallFliesAPathAwayFromIt) {
  // The whole controller, from a start 0.2 m from a wall (its body touching): the path away is
  // flown to its end without a brake; a path along the wall is refused.
  ControllerConfig cfg;
  const auto wall = boxes_field({{Eigen::Vector3d(2.2, -5, 0), Eigen::Vector3d(3.0, 5, 3)}});
  Loop loop(cfg, wall);
  loop.vehicle.position = Eigen::Vector3d(2.0, 0, 1);
  loop.run(0.1);
  loop.send_path({{2.0, 0, 1}, {0.5, 0, 1}}, {0, 0}, 1);
  loop.step();
  ASSERT_EQ(loop.controller.status().state, ControllerState::kTracking) << loop.controller.status().reason;
  loop.track_to_end();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kHolding) << loop.controller.status().reason;
  EXPECT_EQ(loop.controller.counters().brakes, 0);
  EXPECT_NEAR(loop.vehicle.position.x(), 0.5, 0.05);

  Loop along(cfg, wall);
  along.vehicle.position = Eigen::Vector3d(2.0, 0, 1);
  along.run(0.1);
  along.send_path({{2.0, 0, 1}, {2.0, -3, 1}}, {0, 0}, 1);
  along.step();
  EXPECT_EQ(along.controller.status().state, ControllerState::kRejected);
  EXPECT_EQ(along.controller.counters().unsafe, 1);
}

// What a solid the body touches does to the vehicle: it stays where it was.
static void hold(PointMass& vehicle, const Eigen::Vector3d& at) {
  vehicle.position = at;
  vehicle.velocity.setZero();
}

TEST(Safety, AVehicleHeldFarFromItsReferenceBrakesInsteadOfChasingIt) {
  // The vehicle is held where it is (a wall it touches stops every step): the reference runs on,
  // and once it is max_tracking_error ahead the controller stops and says so; the planner plans
  // again from where the vehicle is. Free, the same flight never comes near that error.
  ControllerConfig cfg;
  for (const bool held : {false, true}) {
    Loop loop(cfg, boxes_field({}));
    loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
    loop.run(0.1);
    loop.send_path({{0, 0, 1}, {6, 0, 1}}, {0, 0}, 3);
    loop.run(0.5);
    ASSERT_EQ(loop.controller.status().state, ControllerState::kTracking);
    double worst = 0.0;
    for (int i = 0; i < 300 && loop.controller.status().state == ControllerState::kTracking; ++i) {
      const Eigen::Vector3d p = loop.vehicle.position;
      loop.step();
      worst = std::max(worst, loop.last.status.tracking_error);
      if (held) hold(loop.vehicle, p);
    }
    if (!held) {
      EXPECT_LT(worst, 0.2);
      EXPECT_EQ(loop.controller.counters().off_track, 0);
      continue;
    }
    EXPECT_EQ(loop.controller.status().state, ControllerState::kBraking);
    EXPECT_NE(loop.controller.status().reason.find("from its reference"), std::string::npos)
        << loop.controller.status().reason;
    EXPECT_EQ(loop.controller.counters().off_track, 1);
    EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
    EXPECT_LE(worst, cfg.safety.max_tracking_error + 0.02);
  }
  cfg.safety.max_tracking_error = 0.0;  // off: it chases on
  Loop off(cfg, boxes_field({}));
  off.vehicle.position = Eigen::Vector3d(0, 0, 1);
  off.run(0.1);
  off.send_path({{0, 0, 1}, {6, 0, 1}}, {0, 0}, 3);
  for (int i = 0; i < 250; ++i) {
    const Eigen::Vector3d p = off.vehicle.position;
    off.step();
    hold(off.vehicle, p);
  }
  EXPECT_EQ(off.controller.status().state, ControllerState::kTracking);
  EXPECT_EQ(off.controller.counters().off_track, 0);
}

TEST(Safety, BrakesOnAPredictedCollisionAndSaysWhy) {
  ControllerConfig cfg;
  auto free_field = boxes_field({});
  Loop loop(cfg, free_field);
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 5);
  loop.run(2.0);
  ASSERT_EQ(loop.controller.status().state, ControllerState::kTracking);
  const double x = loop.vehicle.position.x();
  // The map now shows a wall 1.2 m ahead: within the 2 s horizon at ≤ 1 m/s.
  loop.field = boxes_field({{Eigen::Vector3d(x + 1.2, -3, 0), Eigen::Vector3d(x + 1.4, 3, 3)}});
  loop.run_until([&] { return loop.controller.status().state != ControllerState::kTracking; }, 0.05);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kBraking);
  EXPECT_NE(loop.controller.status().reason.find("predicted collision"), std::string::npos);
  EXPECT_EQ(loop.controller.status().plan_id, 5);
  EXPECT_TRUE(loop.last.status_changed);
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
  EXPECT_EQ(loop.controller.trajectory(), nullptr);
  EXPECT_EQ(loop.controller.counters().brakes, 1);
  // It stays stopped (hovering) until the planner sends a new path, and never reaches the wall.
  loop.run(3.0);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kBraking);
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
  EXPECT_LT(loop.vehicle.velocity.norm(), 0.05);
  EXPECT_GT(loop.field->distance(loop.vehicle.position), cfg.clearance.half_size);
  loop.send_path({{loop.vehicle.position}, {loop.vehicle.position + Eigen::Vector3d(0, 2, 0)}}, {0, 0}, 6);
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kTracking);
}

TEST(Safety, IgnoresObstaclesBeyondTheHorizonAndOffThePath) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {6, 0, 1}, {12, 0, 1}}, {0, 0, 0}, 1);
  loop.run(1.0);
  // 8 m ahead (beyond 2 s) and 1 m beside the path: no reason to brake now.
  loop.field = boxes_field({{Eigen::Vector3d(9, -3, 0), Eigen::Vector3d(9.2, 3, 3)},
                            {Eigen::Vector3d(2, 1.0, 0), Eigen::Vector3d(6, 1.2, 3)}});
  loop.run(1.0);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kTracking);
  // As the vehicle closes in, the wall enters the horizon and it brakes in time.
  loop.run_until([&] { return loop.controller.status().state == ControllerState::kBraking; }, 10.0);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kBraking);
  loop.run(3.0);
  EXPECT_GT(loop.field->distance(loop.vehicle.position), cfg.clearance.half_size);
}

TEST(Safety, BrakesWhenANewMapPutsAWallsEndWithinTheTurnedBodysReach) {
  // An optimised trajectory's far part lay outside the mapper's window (free) when it was made;
  // on arrival its turned body's corner met a jamb's end that the plain bound let pass (env3, 50
  // samples, seed 3, t = 141.7 s). Heading 45° off the way, 0.33 m beside a post: above the
  // 0.30 m brake bound, within the corner's 0.354 m.
  ControllerConfig cfg;
  Loop loop(cfg, std::make_shared<FreeField>());
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.vehicle.yaw = M_PI / 4;
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {M_PI / 4, M_PI / 4}, 3);
  loop.run(2.0);
  ASSERT_EQ(loop.controller.status().state, ControllerState::kTracking);
  ASSERT_TRUE(loop.controller.trajectory()->optimized);
  const double x = loop.vehicle.position.x();
  const auto post = std::make_shared<PostField>(Eigen::Vector2d(x + 1.2, 0.33));
  loop.field = post;
  loop.run_until([&] { return loop.controller.status().state != ControllerState::kTracking; }, 0.05);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kBraking);
  EXPECT_EQ(loop.controller.counters().brakes, 1);
  loop.run(3.0);
  EXPECT_LT(loop.vehicle.position.x(), x + 1.2);
  // Faced square to the post, the same trajectory flies on past it.
  Loop square(cfg, std::make_shared<FreeField>());
  square.vehicle.position = Eigen::Vector3d(0, 0, 1);
  square.run(0.1);
  square.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 3);
  square.run(2.0);
  square.field = std::make_shared<PostField>(Eigen::Vector2d(square.vehicle.position.x() + 1.2, 0.33));
  square.run(3.0);
  EXPECT_EQ(square.controller.counters().brakes, 0);
  EXPECT_GT(square.vehicle.position.x(), x + 1.5);
}

TEST(Safety, StaleOdometryStopsTheVehicle) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 1);
  loop.run(2.0);
  ASSERT_EQ(loop.controller.status().state, ControllerState::kTracking);
  loop.send_odometry = false;
  loop.run(0.19);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kTracking);  // 0.19 s: not yet
  loop.run(0.03);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kStaleInput);
  EXPECT_NE(loop.controller.status().reason.find("odometry"), std::string::npos);
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
  EXPECT_EQ(loop.controller.trajectory(), nullptr);
  EXPECT_EQ(loop.controller.counters().stale_stops, 1);
  // Still stale: the status does not flap and the counter does not grow.
  loop.run(1.0);
  EXPECT_FALSE(loop.last.status_changed);
  EXPECT_EQ(loop.controller.counters().stale_stops, 1);
  // Fresh again: idle, hovering, waiting for a path; the old trajectory is not resumed.
  loop.send_odometry = true;
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kIdle);
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
}

TEST(Safety, StaleOrMissingEsdfStopsTheVehicle) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.send_esdf = false;
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 1);
  loop.run(0.5);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kStaleInput);
  EXPECT_EQ(loop.controller.status().reason, "no ESDF yet");
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
  // The path waits for a map (within path.max_age) and is flown once one arrives.
  loop.send_esdf = true;
  loop.controller.on_esdf(loop.field, loop.now);
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kTracking);
  loop.run(2.0);
  loop.send_esdf = false;
  loop.run(cfg.safety.max_esdf_age + 0.05);
  EXPECT_EQ(loop.controller.status().state, ControllerState::kStaleInput);
  EXPECT_NE(loop.controller.status().reason.find("ESDF older"), std::string::npos);
}

TEST(Safety, APathWaitingTooLongForInputsIsRejected) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.send_esdf = false;
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 3);
  loop.run(cfg.path.max_age + 0.5);
  loop.send_esdf = true;
  loop.controller.on_esdf(loop.field, loop.now);
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kRejected);
  EXPECT_NE(loop.controller.status().reason.find("older than"), std::string::npos);
}

namespace {

struct BadPath {
  const char* name;
  std::vector<Eigen::Vector3d> waypoints;
  std::vector<double> yaws;
  double max_speed;
  const char* why;  // part of the reason
};

}  // namespace

TEST(Safety, BadPathsAreRejectedAndCounted) {
  ControllerConfig cfg;
  cfg.path.max_waypoints = 50;
  const double nan = std::nan("");
  std::vector<Eigen::Vector3d> many;
  for (int i = 0; i < 51; ++i) many.emplace_back(0.01 * i, 0, 1);
  const std::vector<BadPath> bad = {
      {"empty", {}, {}, 0, "empty path"},
      {"nan waypoint", {{0, 0, 1}, {nan, 0, 1}}, {0, 0}, 0, "not finite"},
      {"inf waypoint", {{0, 0, 1}, {1, INFINITY, 1}}, {0, 0}, 0, "not finite"},
      {"nan yaw", {{0, 0, 1}, {1, 0, 1}}, {0, nan}, 0, "not finite"},
      {"jump", {{0, 0, 1}, {1, 0, 1}, {30, 0, 1}}, {0, 0, 0}, 0, "jump of"},
      {"too many", many, std::vector<double>(51, 0.0), 0, "51 waypoints"},
      {"far start", {{5, 0, 1}, {6, 0, 1}}, {0, 0}, 0, "from the vehicle"},
      {"negative speed", {{0, 0, 1}, {1, 0, 1}}, {0, 0}, -1, "max_speed"},
      {"yaw count", {{0, 0, 1}, {1, 0, 1}}, {0}, 0, "differ in number"},
  };
  Loop loop(cfg, boxes_field({}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  int64_t id = 10;
  for (const auto& b : bad) {
    loop.send_path(b.waypoints, b.yaws, id, b.max_speed);
    loop.step();
    EXPECT_EQ(loop.controller.status().state, ControllerState::kRejected) << b.name;
    EXPECT_EQ(loop.controller.status().plan_id, id) << b.name;
    EXPECT_NE(loop.controller.status().reason.find(b.why), std::string::npos)
        << b.name << ": " << loop.controller.status().reason;
    EXPECT_TRUE(loop.last.status_changed) << b.name;
    EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold) << b.name;
    ++id;
  }
  EXPECT_EQ(loop.controller.counters().rejected, static_cast<int64_t>(bad.size()));
  EXPECT_EQ(loop.controller.counters().trajectories, 0);
  EXPECT_LT(loop.vehicle.position.norm() - 1.0, 0.01);  // never moved
}

TEST(Safety, ABadPathStopsTheCurrentTrajectory) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {10, 0, 1}}, {0, 0}, 1);
  loop.run(2.0);
  loop.send_path({}, {}, 2);
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kRejected);
  EXPECT_EQ(loop.controller.trajectory(), nullptr);
  EXPECT_EQ(loop.last.command.mode, Command::Mode::kHold);
}

TEST(Safety, APathThroughAWallIsRejectedAsUnsafe) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({{Eigen::Vector3d(2, -3, 0), Eigen::Vector3d(2.2, 3, 3)}}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {4, 0, 1}}, {0, 0}, 9);
  loop.step();
  EXPECT_EQ(loop.controller.status().state, ControllerState::kRejected);
  EXPECT_NE(loop.controller.status().reason.find("no safe trajectory"), std::string::npos);
  EXPECT_EQ(loop.controller.counters().unsafe, 1);
  EXPECT_EQ(loop.controller.counters().rejected, 0);
}

TEST(Safety, OnlyTheNewestPendingPathIsFlown) {
  ControllerConfig cfg;
  Loop loop(cfg, boxes_field({}));
  loop.vehicle.position = Eigen::Vector3d(0, 0, 1);
  loop.run(0.1);
  loop.send_path({{0, 0, 1}, {3, 0, 1}}, {0, 0}, 1);
  loop.send_path({{0, 0, 1}, {0, 3, 1}}, {0, 0}, 2);
  loop.step();
  EXPECT_EQ(loop.controller.status().plan_id, 2);
  EXPECT_EQ(loop.controller.counters().superseded, 1);
  ASSERT_NE(loop.last.new_trajectory, nullptr);
  EXPECT_EQ(loop.last.new_trajectory->plan_id, 2);
  EXPECT_EQ(loop.last.new_trajectory->start_utime, loop.now - 10'000);
}

TEST(Safety, IsDeterministic) {
  // The same inputs at the same message times give bit-identical commands.
  const auto run = [] {
    ControllerConfig cfg;
    const SyntheticScene scene = make_cluttered_scene(77);
    Loop loop(cfg, std::make_shared<GridDistanceField>(scene.field));
    loop.vehicle.position = scene.path.front();
    loop.run(0.1);
    loop.send_path(scene.path, scene.yaws, 1);
    std::vector<double> out;
    for (int i = 0; i < 500; ++i) {
      loop.step();
      out.push_back(loop.last.command.velocity.x());
      out.push_back(loop.last.command.yaw);
    }
    return out;
  };
  EXPECT_EQ(run(), run());
}
