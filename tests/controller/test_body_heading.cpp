// Headings squared to the obstacles a path passes close to (body_heading.hpp).
#include <gtest/gtest.h>

#include "fields.hpp"
#include "semx/controller/body_heading.hpp"
#include "semx/controller/clearance.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/trajectory_generator.hpp"

namespace semx::controller {
namespace {

using test::FreeField;
using test::PostField;

constexpr double kHalf = 0.25;

// The vehicle at rest at the path's first point, heading as the planner asks there.
StartState at_rest(const std::vector<Eigen::Vector3d>& pts, const std::vector<double>& yaws) {
  StartState s;
  s.position = pts[0];
  s.yaw = yaws[0];
  return s;
}

double reach_toward_post(const Eigen::Vector3d& p, const Eigen::Vector2d& post, double yaw) {
  const Eigen::Vector2d d = (post - p.head<2>()).normalized();
  return footprint_reach(Eigen::Vector3d(d.x(), d.y(), 0.0), yaw, kHalf, 0.15);
}

TEST(BodyHeading, APointBesideAnEdgeTurnsTheBodyToFaceIt) {
  // A door leaf's edge 0.36 m beside the middle point, the path heading diagonally: the corner
  // would reach 0.354 m toward it. Only that point turns, by 45°, to a face.
  const Eigen::Vector2d post(2.0, 0.36);
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {2, 0, 1}, {4, 0, 1}};
  std::vector<double> yaws = {M_PI / 4, M_PI / 4, M_PI / 4};
  ASSERT_GT(reach_toward_post(pts[1], post, yaws[1]), 0.35);
  EXPECT_EQ(square_headings_near_obstacles(pts, yaws, PostField(post), std::sqrt(2.0) * kHalf + 0.02), 1);
  EXPECT_DOUBLE_EQ(yaws[0], M_PI / 4);
  EXPECT_DOUBLE_EQ(yaws[2], M_PI / 4);
  EXPECT_NEAR(std::abs(yaws[1] - M_PI / 4), M_PI / 4, 1e-9) << "a quarter turn at most, the smallest";
  EXPECT_NEAR(reach_toward_post(pts[1], post, yaws[1]), kHalf, 1e-9);
}

TEST(BodyHeading, TurnsByTheSmallestAngleAndKeepsHeadingsUnwrapped) {
  const Eigen::Vector2d post(0.0, 0.3);  // straight +y of the point
  const std::vector<Eigen::Vector3d> pts = {{5, 5, 1}, {0, 0, 1}};
  for (const double yaw : {0.3, -0.3, 1.2, 2.0, 20 * M_PI + 0.3, -20 * M_PI - 2.0}) {
    std::vector<double> yaws = {0.0, yaw};
    square_headings_near_obstacles(pts, yaws, PostField(post), 0.4);
    EXPECT_LE(std::abs(yaws[1] - yaw), M_PI / 4 + 1e-9) << yaw;
    EXPECT_NEAR(std::remainder(yaws[1], M_PI / 2), 0.0, 1e-9) << yaw << " -> " << yaws[1];
  }
}

TEST(BodyHeading, LeavesPointsWithRoomOrOnARidgeAlone) {
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}};
  std::vector<double> yaws = {0.7, 0.7, 0.7};
  // The start is the vehicle's heading, whatever is near it; the others have 0.5 m of room.
  EXPECT_EQ(square_headings_near_obstacles(pts, yaws, PostField(Eigen::Vector2d(0.0, 0.1)), 0.374), 0);
  EXPECT_EQ(square_headings_near_obstacles(pts, yaws, PostField(Eigen::Vector2d(1.0, 0.5)), 0.374), 0);
  // A doorway's centre line: close, but no direction to face.
  EXPECT_EQ(square_headings_near_obstacles(pts, yaws, FreeField(0.3), 0.374), 0);
  EXPECT_EQ(square_headings_near_obstacles(pts, yaws, PostField(Eigen::Vector2d(1.0, 0.3)), 0.0), 0);
  EXPECT_EQ(yaws, std::vector<double>({0.7, 0.7, 0.7}));
}

TEST(BodyHeading, TheFallbackThroughATightPointKeepsTheTurnedBodyOffTheEdge) {
  // The DEP collision of env3, seed 2: the fallback (the path exactly) through a point 0.36 m
  // from an edge, heading diagonally. With square_headings its body faces the edge there and the
  // whole curve passes the turned-body rule; without, it does not.
  ControllerConfig cfg;
  cfg.optimizer.max_iterations = 0;  // the fallback
  const Eigen::Vector2d edge(2.0, 0.36);
  const PostField field(edge);
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {2, 0, 1}, {4, 0, 1}};
  const std::vector<double> yaws = {M_PI / 4, M_PI / 4, M_PI / 4};
  const StartState start = at_rest(pts, yaws);
  const TrajectoryGenerator squared(cfg);
  const GenerationResult r = squared.generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.squared_headings, 1);
  const ClearanceRule body = squared.flight_rule(true);
  EXPECT_TRUE(check_clearance(r.trajectory, field, 0, r.trajectory.duration(), body).ok);

  cfg.clearance.square_headings = false;
  cfg.clearance.square_fallback = false;
  const GenerationResult plain = TrajectoryGenerator(cfg).generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(plain.ok) << plain.reason;
  EXPECT_EQ(plain.squared_headings, 0);
  EXPECT_EQ(plain.repaired_headings, 0);
  EXPECT_FALSE(check_clearance(plain.trajectory, field, 0, plain.trajectory.duration(), body).ok);

  // Without the squared path point, the held heading (square_fallback) keeps the body off too.
  cfg.clearance.square_fallback = true;
  const GenerationResult held = TrajectoryGenerator(cfg).generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(held.ok) << held.reason;
  EXPECT_EQ(held.squared_headings, 0);
  EXPECT_GE(held.repaired_headings, 1);
  EXPECT_TRUE(check_clearance(held.trajectory, field, 0, held.trajectory.duration(), body).ok);
}

TEST(BodyHeading, HoldingTheHeadingReplacesTheKnotsAroundTheInstant) {
  std::vector<double> times = {0.0, 1.0, 2.0, 3.0, 4.0};
  std::vector<double> yaws = {0.0, 0.7, 0.7, 0.7, 0.7};
  // The obstacle along +y: a face looks along it at every quarter turn; the nearest to 0.7 rad is 0.
  const HeadingRamp square =
      heading_for_limits(0.7, {ReachLimit{2.1, Eigen::Vector3d(0, 1, 0), 0.3}}, 0.5, kHalf, 0.15);
  EXPECT_NEAR(square.yaw, 0.0, 1e-12);
  EXPECT_EQ(square.rate, 0.0) << "one instant: a steady heading";
  ASSERT_TRUE(hold_heading(times, yaws, 2.1, 2.1, 0.3, square));
  EXPECT_EQ(times, std::vector<double>({0.0, 1.0, 1.8, 2.4, 3.0, 4.0}));
  ASSERT_EQ(yaws.size(), 6u);
  EXPECT_NEAR(yaws[2], 0.0, 1e-12);
  EXPECT_NEAR(yaws[3], 0.0, 1e-12);
  EXPECT_EQ(yaws.front(), 0.0);
  EXPECT_EQ(yaws.back(), 0.7);
  // Near the ends the hold shrinks so the vehicle's and the goal's headings stay first and last.
  std::vector<double> t2 = {0.0, 1.0}, y2 = {0.0, 0.0};
  ASSERT_TRUE(hold_heading(t2, y2, 0.9, 0.9, 0.3, HeadingRamp{0.9, 0.2, 0.0}));
  EXPECT_EQ(t2.front(), 0.0);
  EXPECT_EQ(t2.back(), 1.0);
  EXPECT_EQ(y2.back(), 0.0);
  EXPECT_NEAR(y2[1], 0.2, 1e-12);
  // Instants outside the target, or in the wrong order: nothing to do.
  std::vector<double> t3 = times, y3 = yaws;
  EXPECT_FALSE(hold_heading(t3, y3, 4.5, 4.5, 0.3, HeadingRamp{}));
  EXPECT_FALSE(hold_heading(t3, y3, 2.5, 2.0, 0.3, HeadingRamp{}));
  EXPECT_EQ(t3, times);
  // A turning hold: its knots lie on the ramp.
  std::vector<double> t4 = {0.0, 4.0}, y4 = {0.0, 0.0};
  ASSERT_TRUE(hold_heading(t4, y4, 2.0, 2.5, 0.3, HeadingRamp{2.0, 0.1, 0.2}));
  EXPECT_EQ(t4, std::vector<double>({0.0, 1.7, 2.8, 4.0}));
  EXPECT_NEAR(y4[1], 0.1 - 0.2 * 0.3, 1e-12);
  EXPECT_NEAR(y4[2], 0.1 + 0.2 * 0.8, 1e-12);
}

TEST(BodyHeading, TwoJambsThatWantDifferentSquaresGetOneHeadingBetweenThem) {
  // A door of env3's east rooms, as the controller met it (semx-controller-replay): the curve
  // passes the two jamb ends 0.06 m and 0.06 s apart, their directions 173° and 23° (away from
  // each), 0.321 and 0.333 m of reach allowed; then the near jamb again (0.327 m), and the far
  // side's jamb, -24° and 0.327 m, 0.3 s later. Either near jamb's square heading is diagonal to the other.
  const auto unit = [](double deg) {
    return Eigen::Vector3d(std::cos(deg * M_PI / 180), std::sin(deg * M_PI / 180), 0.0);
  };
  const ReachLimit a{8.17, unit(172.8), 0.321}, b{8.11, unit(23.2), 0.333}, c{8.47, unit(-24.2), 0.327},
      b2{8.13, unit(23.0), 0.327};
  const auto meets = [&](const ReachLimit& l, const HeadingRamp& h) {
    return footprint_reach(l.direction, h.at(l.time), kHalf, 0.15) <= l.allowed;
  };
  const double yaw = 23.3 * M_PI / 180;  // the curve's own heading there
  const double rate = 0.5;               // rad/s, half the vehicle's yaw rate
  const HeadingRamp square_a = heading_for_limits(yaw, {a}, rate, kHalf, 0.15);
  const HeadingRamp square_b = heading_for_limits(yaw, {b}, rate, kHalf, 0.15);
  EXPECT_TRUE(meets(a, square_a));
  EXPECT_FALSE(meets(b, square_a));
  EXPECT_TRUE(meets(b, square_b));
  EXPECT_FALSE(meets(a, square_b));
  const HeadingRamp both = heading_for_limits(yaw, {a, b}, rate, kHalf, 0.15);
  EXPECT_TRUE(meets(a, both)) << both.yaw * 180 / M_PI;
  EXPECT_TRUE(meets(b, both)) << both.yaw * 180 / M_PI;
  EXPECT_LE(std::abs(both.yaw - yaw), M_PI / 4 + 1e-9);
  EXPECT_LE(std::abs(both.rate), rate + 1e-12);
  // With the far jamb too no steady heading is enough; one that turns, slower than `rate`, is.
  const HeadingRamp steady = heading_for_limits(yaw, {a, b, b2, c}, 0.0, kHalf, 0.15);
  EXPECT_FALSE(meets(a, steady) && meets(b, steady) && meets(b2, steady) && meets(c, steady))
      << steady.yaw * 180 / M_PI;
  const HeadingRamp turning = heading_for_limits(yaw, {a, b, b2, c}, rate, kHalf, 0.15);
  EXPECT_TRUE(meets(a, turning) && meets(b, turning) && meets(b2, turning) && meets(c, turning))
      << turning.yaw * 180 / M_PI << " " << turning.rate;
  EXPECT_NE(turning.rate, 0.0);
  EXPECT_LE(std::abs(turning.rate), rate + 1e-12);
  // A heading that already meets one limit with the most room stays where it is.
  EXPECT_NEAR(heading_for_limits(0.0, {ReachLimit{1.0, unit(90), 0.3}}, rate, kHalf, 0.15).yaw, 0.0, 1e-12);
}

// The two jambs of a doorway, vertical posts at (x, ±half_gap): the distance to the nearer one.
class DoorwayField : public DistanceField {
 public:
  DoorwayField(double x, double half_gap)
      : DoorwayField(Eigen::Vector2d(x, half_gap), Eigen::Vector2d(x, -half_gap)) {}
  DoorwayField(const Eigen::Vector2d& a, const Eigen::Vector2d& b) : a_(a), b_(b) {}
  double distance(const Eigen::Vector3d& p, Eigen::Vector3d* g = nullptr) const override {
    const double da = a_.distance(p, g);
    Eigen::Vector3d gb;
    const double db = b_.distance(p, &gb);
    if (db < da && g) *g = gb;
    return std::min(da, db);
  }
  double lipschitz() const override { return 1.0; }

 private:
  PostField a_, b_;
};

TEST(BodyHeading, AnOptimisedCurveThroughADoorwayHoldsItsHeadingSquareInsteadOfTakingTheFallback) {
  // A doorway 0.72 m between the jambs' ends (ESDF 0.36 on its centre line), no path point in it,
  // the camera looking 45° off the direction of travel: the corner would reach 0.374 m toward a
  // jamb. Without the repair the whole path goes to the fallback (half speed, a stop at every
  // waypoint); with it the optimised curve is flown, its body square to the jambs in the doorway.
  const DoorwayField field(2.0, 0.36);
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {1.2, 0, 1}, {2.8, 0, 1}, {4, 0, 1}};
  const std::vector<double> yaws(pts.size(), M_PI / 4);
  const StartState start = at_rest(pts, yaws);
  ControllerConfig cfg;
  cfg.clearance.heading_repairs = 0;
  const GenerationResult plain = TrajectoryGenerator(cfg).generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(plain.ok) << plain.reason;
  EXPECT_FALSE(plain.trajectory.optimized);
  EXPECT_EQ(plain.cause, FallbackCause::kTooClose);

  cfg.clearance.heading_repairs = 8;
  const TrajectoryGenerator gen(cfg);
  const GenerationResult r = gen.generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.trajectory.optimized) << r.reason;
  EXPECT_GE(r.repaired_headings, 1);
  EXPECT_TRUE(check_clearance(r.trajectory, field, 0, r.trajectory.duration(), gen.generation_rule(true)).ok);
  EXPECT_LT(r.trajectory.duration(), 0.6 * plain.trajectory.duration());
  // The goal keeps the heading the planner asked for.
  EXPECT_NEAR(r.trajectory.yaw.evaluate(r.trajectory.duration(), 0)(0), yaws.back(), 1e-9);
}

TEST(BodyHeading, StaggeredJambsGetOneHeadingForBothInsteadOfTheFallback) {
  // The jambs' ends 0.68 m apart and 0.1 m apart along the way, the camera 35° off the direction
  // of travel. Holding each jamb's square in turn, the later hold replaced the earlier one and
  // the curve failed again at the first jamb: the path was flown slowed or on the fallback. The
  // holds joined, one heading (or a slow turn) meets both.
  const DoorwayField field(Eigen::Vector2d(2.0, 0.34), Eigen::Vector2d(2.1, -0.34));
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {1.2, 0, 1}, {2.8, 0, 1}, {4, 0, 1}};
  const std::vector<double> yaws(pts.size(), 35.0 * M_PI / 180);
  const StartState start = at_rest(pts, yaws);
  ControllerConfig cfg;
  cfg.clearance.heading_repairs = 0;
  const GenerationResult plain = TrajectoryGenerator(cfg).generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(plain.ok) << plain.reason;
  EXPECT_FALSE(plain.trajectory.optimized);

  cfg.clearance.heading_repairs = 8;
  cfg.clearance.join_holds = false;
  const GenerationResult apart = TrajectoryGenerator(cfg).generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(apart.ok) << apart.reason;
  EXPECT_TRUE(apart.slowed || !apart.trajectory.optimized) << "each hold undoes the other";

  cfg.clearance.join_holds = true;
  const TrajectoryGenerator gen(cfg);
  const GenerationResult r = gen.generate(pts, yaws, start, 0.0, field);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.trajectory.optimized) << r.reason;
  EXPECT_FALSE(r.slowed) << r.reason;
  EXPECT_GE(r.repaired_headings, 2);
  EXPECT_TRUE(check_clearance(r.trajectory, field, 0, r.trajectory.duration(), gen.generation_rule(true)).ok);
  EXPECT_LT(r.trajectory.duration(), 0.65 * plain.trajectory.duration());
  EXPECT_NEAR(r.trajectory.yaw.evaluate(r.trajectory.duration(), 0)(0), yaws.back(), 1e-9);
}

}  // namespace
}  // namespace semx::controller
