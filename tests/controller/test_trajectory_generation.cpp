// Trajectory generation: limits on every sample, clearance on random cluttered ESDFs, the yaw
// profile, the fallback and when there is no trajectory at all.
#include <gtest/gtest.h>

#include <random>

#include "fields.hpp"
#include "semx/controller/fallback.hpp"
#include "semx/controller/time_allocation.hpp"
#include "semx/controller/trajectory_generator.hpp"
#include "semx/core/angles.hpp"
#include "semx/fixtures/synthetic_scene.hpp"

using namespace semx::controller;
using semx::controller::test::FreeField;
using semx::controller::test::PostField;
using semx::controller::test::TubeField;

namespace {

constexpr double kSampleDt = 0.001;  // s: far denser than anything the generator does

struct Extremes {
  double speed = 0, acceleration = 0, yaw_rate = 0, min_distance = 1e300;
};

Extremes sample_all(const Trajectory& t, const DistanceField* field = nullptr) {
  Extremes e;
  for (double s = 0; s <= t.duration() + kSampleDt; s += kSampleDt) {
    const TrajectoryPoint p = t.sample(s);
    e.speed = std::max(e.speed, p.velocity.norm());
    e.acceleration = std::max(e.acceleration, p.acceleration.norm());
    e.yaw_rate = std::max(e.yaw_rate, std::abs(p.yaw_rate));
    if (field) e.min_distance = std::min(e.min_distance, field->distance(p.position));
  }
  return e;
}

double distance_to_polyline(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& p) {
  double best = 1e300;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const Eigen::Vector3d d = pts[i + 1] - pts[i];
    const double u = std::clamp((p - pts[i]).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (pts[i] + u * d)).norm());
  }
  return best;
}

// The fallback as a trajectory, checking that it is at pts[i], at rest, at point_times[i] for
// every i >= from.
Trajectory stops_at_every_point(const FallbackSpline& fb, const std::vector<Eigen::Vector3d>& pts,
                                std::size_t from) {
  EXPECT_EQ(fb.point_times.size(), pts.size());
  Trajectory t;
  t.position = fb.spline;
  for (std::size_t i = from; i < std::min(pts.size(), fb.point_times.size()); ++i) {
    const TrajectoryPoint p = t.sample(fb.point_times[i]);
    EXPECT_LT((p.position - pts[i]).norm(), 1e-12) << i;
    EXPECT_LT(p.velocity.norm(), 1e-12) << i;
  }
  return t;
}

std::vector<double> unwrapped(std::vector<double> yaws) {
  for (std::size_t k = 1; k < yaws.size(); ++k) yaws[k] = semx::core::unwrap_near(yaws[k], yaws[k - 1]);
  return yaws;
}

StartState at_rest(const Eigen::Vector3d& p, double yaw = 0) {
  StartState s;
  s.position = p;
  s.yaw = yaw;
  return s;
}

}  // namespace

TEST(TimeAllocation, StartsStopsAndSlowsAtCorners) {
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {4, 0, 1}, {4, 4, 1}, {8, 4, 1}};
  const TimedPolyline tp(pts, 0.0, 1.0, 2.0, 0.25);
  EXPECT_LT((tp.position(0) - pts.front()).norm(), 1e-12);
  EXPECT_LT((tp.position(tp.duration()) - pts.back()).norm(), 1e-12);
  EXPECT_NEAR(tp.length(), 12.0, 1e-12);
  ASSERT_EQ(tp.point_times().size(), 4u);
  for (std::size_t i = 0; i < pts.size(); ++i)
    EXPECT_LT((tp.position(tp.point_times()[i]) - pts[i]).norm(), 1e-9);
  const double corner = TimedPolyline::corner_speed(M_PI / 2, 1.0, 2.0, 0.25);
  EXPECT_NEAR(corner, 2.0 * 0.25 / (2 * std::sin(M_PI / 4)), 1e-12);
  EXPECT_NEAR(tp.speed(tp.point_times()[1]), corner, 1e-6);
  EXPECT_NEAR(tp.speed(1.0 + 0.5), 1.0, 1e-9);  // cruising after 0.5 s of acceleration
  double prev = 0;
  for (double t = 0; t <= tp.duration(); t += 0.01) {
    EXPECT_LE(tp.speed(t), 1.0 + 1e-12);
    const double s = (tp.position(t) - pts.front()).norm();
    if (t < tp.point_times()[1]) {
      EXPECT_GE(s, prev - 1e-12);  // moves forward along the first segment
      prev = s;
    }
  }
}

TEST(TimeAllocation, ACappedSegmentIsFlownNoFasterThanItsCap) {
  // Three straight 4 m segments, the middle one capped at 0.5 m/s: full speed before and after it,
  // at most 0.5 on it, and slower overall than with no cap.
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {4, 0, 1}, {8, 0, 1}, {12, 0, 1}};
  const TimedPolyline capped(pts, 0.0, 1.0, 2.0, 0.25, {1.0, 0.5, 1.0});
  const TimedPolyline free(pts, 0.0, 1.0, 2.0, 0.25);
  double before = 0, on = 0, after = 0;
  for (double t = 0; t <= capped.duration(); t += 0.01) {
    const double x = capped.position(t).x();
    double& top = x < 4 ? before : x <= 8 ? on : after;
    top = std::max(top, capped.speed(t));
  }
  EXPECT_NEAR(before, 1.0, 1e-9);
  EXPECT_LE(on, 0.5 + 1e-9);
  EXPECT_NEAR(after, 1.0, 1e-9);
  EXPECT_GT(capped.duration(), free.duration() + 3.5);  // 4 m at half speed, less the ramps
  // A cap list of the wrong length is ignored.
  EXPECT_DOUBLE_EQ(TimedPolyline(pts, 0.0, 1.0, 2.0, 0.25, {0.5}).duration(), free.duration());
}

TEST(TrajectoryGeneration, StraightPathInFreeSpaceIsFastSmoothAndEndsAtRest) {
  const ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {10, 0, 1}};
  const GenerationResult r = gen.generate(pts, {0.0, 0.0}, at_rest(pts[0]), 0.0, FreeField());
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.trajectory.optimized);
  const Trajectory& t = r.trajectory;
  EXPECT_LT((t.position_at(0) - pts[0]).norm(), 1e-9);
  EXPECT_LT((t.end_position() - pts[1]).norm(), 1e-9);
  EXPECT_LT(t.sample(t.duration()).velocity.norm(), 1e-9);
  EXPECT_LT(t.sample(0).velocity.norm(), 1e-9);
  EXPECT_GT(t.sample(0.5 * t.duration()).velocity.x(), 0.95);  // cruises near the limit
  EXPECT_LT(t.duration(), 10.0 / 1.0 + 2.0);                   // ≈ L/v + the ramps
  const Extremes e = sample_all(t);
  EXPECT_LE(e.speed, 1.0 + 1e-6);
  EXPECT_LE(e.acceleration, 2.0 + 1e-6);
}

TEST(TrajectoryGeneration, LimitsAreRespectedOnEverySample) {
  // Random cluttered scenes, random start velocities, random path speed limits and limits.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int checked = 0;
  for (int seed = 0; seed < 16; ++seed) {
    ControllerConfig cfg;
    cfg.limits.max_velocity = 0.6 + 0.3 * (seed % 4);
    cfg.limits.max_acceleration = 1.0 + 0.5 * (seed % 3);
    cfg.limits.max_yaw_rate = 0.5 + 0.25 * (seed % 5);
    const TrajectoryGenerator gen(cfg);
    const SyntheticScene scene = make_cluttered_scene(100 + seed);
    StartState start = at_rest(scene.path.front(), u(rng) * M_PI);
    start.velocity = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
    const double path_speed = seed % 2 ? 0.0 : 0.5 + 0.4 * (u(rng) + 1);
    std::vector<double> yaws = scene.yaws;
    yaws[0] = start.yaw;
    const GenerationResult r = gen.generate(scene.path, unwrapped(yaws), start, path_speed, scene.field);
    ASSERT_TRUE(r.ok) << "seed " << seed << ": " << r.reason;
    const double v_lim = gen.speed_limit(path_speed);
    const Extremes e = sample_all(r.trajectory);
    EXPECT_LE(e.speed, v_lim * (1 + 1e-6)) << "seed " << seed;
    EXPECT_LE(e.acceleration, cfg.limits.max_acceleration * (1 + 1e-6)) << "seed " << seed;
    EXPECT_LE(e.yaw_rate, cfg.limits.max_yaw_rate * (1 + 1e-6)) << "seed " << seed;
    // The bounds the generator used are the convex-hull ones, which the samples confirm.
    EXPECT_LE(e.speed, r.trajectory.max_speed() * (1 + 1e-9));
    ++checked;
  }
  EXPECT_EQ(checked, 16);
}

TEST(TrajectoryGeneration, ClearanceNeverBelowTheBoundOnRandomClutteredEsdfs) {
  const ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const double bound = cfg.clearance.bound();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int optimized = 0;
  const int seeds = 40;
  for (int seed = 0; seed < seeds; ++seed) {
    SceneOptions so;
    so.obstacles = 60 + (seed % 3) * 30;  // denser and denser clutter
    // The path keeps 0.45 m (exact) from the boxes: on the grid the fallback just passes.
    const SyntheticScene scene = make_cluttered_scene(500 + seed, so);
    StartState start = at_rest(scene.path.front(), scene.yaws.front());
    if (seed % 2) start.velocity = 0.8 * Eigen::Vector3d(u(rng), u(rng), 0.2 * u(rng));
    const GenerationResult r = gen.generate(scene.path, unwrapped(scene.yaws), start, 0.0, scene.field);
    ASSERT_TRUE(r.ok) << "seed " << seed << ": " << r.reason;  // the path itself is always safe
    const Extremes e = sample_all(r.trajectory, &scene.field);
    EXPECT_GE(e.min_distance, bound) << "seed " << seed
                                     << (r.trajectory.optimized ? " optimised" : " fallback");
    // The true geometry agrees with the grid to within its interpolation error.
    EXPECT_GE(r.clearance.min_distance, bound);
    optimized += r.trajectory.optimized ? 1 : 0;
  }
  EXPECT_GE(optimized, seeds * 8 / 10) << "the optimiser should usually succeed";
}

TEST(TrajectoryGeneration, OptimiserLowersItsCostAndKeepsTheEnds) {
  const ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const TrajectoryOptimizer opt(cfg.optimizer);
  const SyntheticScene scene = make_cluttered_scene(42);
  PositionSpline s = gen.initial_spline(scene.path, at_rest(scene.path.front()), 1.0);
  const PositionSpline before = s;
  const OptimizerReport r =
      opt.optimize(s, scene.field, 1.0, 2.0, cfg.clearance.bound() + cfg.optimizer.target_margin);
  ASSERT_TRUE(r.ran);
  EXPECT_FALSE(r.failed);
  EXPECT_LT(r.final_cost, r.initial_cost);
  EXPECT_GT(r.iterations, 0);
  for (int i : {0, 1, 2, s.size() - 3, s.size() - 2, s.size() - 1}) {
    EXPECT_EQ(s.control_points()[i], before.control_points()[i]) << i;
  }
}

TEST(TrajectoryGeneration, StartStateIsTheVehiclesAndPathSpeedLowersTheLimit) {
  ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {3, 0, 1}, {3, 3, 1}};
  StartState start = at_rest(pts[0]);
  start.velocity = Eigen::Vector3d(0.5, 0.1, 0.0);
  const GenerationResult r = gen.generate(pts, {0, 0, 0}, start, 0.6, FreeField());
  ASSERT_TRUE(r.ok);
  const TrajectoryPoint p0 = r.trajectory.sample(0);
  EXPECT_LT((p0.position - start.position).norm(), 1e-9);
  EXPECT_LT((p0.velocity - start.velocity / r.time_scale).norm(), 1e-9);
  EXPECT_LE(sample_all(r.trajectory).speed, 0.6 * (1 + 1e-6));
}

TEST(TrajectoryGeneration, YawTurnsTheShortWayToEachWaypointsHeading) {
  ControllerConfig cfg;
  cfg.limits.max_yaw_rate = 0.5;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {4, 0, 1}, {4, 4, 1}};
  // From 3.0 rad to -3.0 rad is +0.28 rad through ±π, not -6 rad.
  const std::vector<double> yaws = unwrapped({3.0, -3.0, -1.5});
  EXPECT_NEAR(yaws[1], 2 * M_PI - 3.0, 1e-12);
  const GenerationResult r = gen.generate(pts, yaws, at_rest(pts[0], 3.0), 0.0, FreeField());
  ASSERT_TRUE(r.ok);
  const Trajectory& t = r.trajectory;
  EXPECT_NEAR(t.sample(0).yaw, 3.0, 1e-9);
  EXPECT_NEAR(semx::core::wrap_angle(t.end_yaw() - (-1.5)), 0.0, 1e-9);
  // Monotone: every sample lies between the start yaw and the next target (no long way round).
  for (double s = 0; s <= t.duration(); s += 0.01) {
    const double y = t.sample(s).yaw;
    EXPECT_GE(y, 3.0 - 1e-9);
    EXPECT_LE(y, yaws[2] + 1e-9);
  }
  EXPECT_LE(sample_all(t).yaw_rate, 0.5 * (1 + 1e-6));
}

TEST(TrajectoryGeneration, ShortPathWithALargeTurnHoversUntilTheHeadingIsReached) {
  ControllerConfig cfg;
  cfg.limits.max_yaw_rate = 0.5;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {0.3, 0, 1}};
  const GenerationResult r = gen.generate(pts, {0.0, 3.0}, at_rest(pts[0]), 0.0, FreeField());
  ASSERT_TRUE(r.ok);
  EXPECT_GE(r.trajectory.duration(), 3.0 / 0.5);  // the turn takes at least 6 s
  EXPECT_NEAR(r.trajectory.end_yaw(), 3.0, 1e-9);
  EXPECT_LT((r.trajectory.end_position() - pts[1]).norm(), 1e-9);
  const Extremes e = sample_all(r.trajectory);
  EXPECT_LE(e.yaw_rate, 0.5 * (1 + 1e-6));
}

TEST(TrajectoryGeneration, DisabledOptimiserFallsBackToThePolylineAtLowerSpeed) {
  ControllerConfig cfg;
  cfg.optimizer.max_iterations = 0;
  const TrajectoryGenerator gen(cfg);
  const SyntheticScene scene = make_cluttered_scene(3);
  const GenerationResult r =
      gen.generate(scene.path, unwrapped(scene.yaws), at_rest(scene.path.front()), 0.0, scene.field);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_FALSE(r.trajectory.optimized);
  EXPECT_NE(r.reason.find("optimiser disabled"), std::string::npos) << r.reason;
  const Extremes e = sample_all(r.trajectory, &scene.field);
  EXPECT_LE(e.speed, cfg.limits.max_velocity * cfg.trajectory.fallback_speed_factor * (1 + 1e-6));
  EXPECT_LE(e.acceleration, cfg.limits.max_acceleration * (1 + 1e-6));
  EXPECT_GE(e.min_distance, cfg.clearance.bound());
  for (double s = 0; s <= r.trajectory.duration(); s += 0.005) {
    ASSERT_LT(distance_to_polyline(scene.path, r.trajectory.position_at(s)), 1e-9) << "off the path at " << s;
  }
}

TEST(TrajectoryGeneration, ImpossibleCorridorFallsBack) {
  // Free only within ~1 cm of a zig-zag: any smooth curve cuts a corner and collides.
  const ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}, {0, 4, 1}};
  const TubeField tube(pts, cfg.clearance.bound() + 0.5 * cfg.clearance.check_spacing + 0.01);
  const GenerationResult r = gen.generate(pts, {0, 0, 0, 0, 0}, at_rest(pts[0]), 0.0, tube);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_FALSE(r.trajectory.optimized);
  EXPECT_NE(r.reason.find("too close"), std::string::npos) << r.reason;
  EXPECT_GE(sample_all(r.trajectory, &tube).min_distance, cfg.clearance.bound());
}

TEST(TrajectoryGeneration, PathThroughAWallHasNoTrajectory) {
  const ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  const std::vector<Box> wall{{Eigen::Vector3d(2.0, -3, 0), Eigen::Vector3d(2.2, 3, 3)}};
  const GridDistanceField field =
      rasterize_boxes(wall, Eigen::Vector3d(-1, -4, 0), 0.1, 60, 80, 30, 2.0, OutsideWindow::kFree);
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1}, {4, 0, 1}};
  const GenerationResult r = gen.generate(pts, {0, 0}, at_rest(pts[0]), 0.0, field);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("no safe trajectory"), std::string::npos) << r.reason;
}

TEST(TrajectoryGeneration, AVehicleTooCloseToAWallMayOnlyEscape) {
  ControllerConfig cfg;
  const std::vector<Box> wall{{Eigen::Vector3d(-1.0, -3, 0), Eigen::Vector3d(-0.35, 3, 3)}};
  const GridDistanceField field =
      rasterize_boxes(wall, Eigen::Vector3d(-2, -4, 0), 0.1, 80, 80, 30, 2.0, OutsideWindow::kFree);
  // A start between the hard bound (half_size, plus the check's pad) and the bound.
  const double hard = cfg.clearance.half_size + 0.5 * field.lipschitz() * cfg.clearance.check_spacing;
  Eigen::Vector3d start(0.0, 0.0, 1.0);
  const double mid = 0.5 * (hard + cfg.clearance.bound());
  while (field.distance(start) >= mid && start.x() > -0.3) start.x() -= 0.001;
  ASSERT_LT(field.distance(start), cfg.clearance.bound());
  ASSERT_GT(field.distance(start), hard);
  {
    const TrajectoryGenerator gen(cfg);
    const std::vector<Eigen::Vector3d> away{start, {3, 0, 1}};
    const GenerationResult r = gen.generate(away, {0, 0}, at_rest(start), 0.0, field);
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_TRUE(r.clearance.escaping);
    EXPECT_GE(sample_all(r.trajectory, &field).min_distance, field.distance(start) - 0.011);
    // Along the wall it would not get out: refused.
    const std::vector<Eigen::Vector3d> along{start, {start.x(), 3, 1}};
    EXPECT_FALSE(gen.generate(along, {0, 0}, at_rest(start), 0.0, field).ok);
  }
  cfg.clearance.allow_escape = false;
  const TrajectoryGenerator strict(cfg);
  EXPECT_FALSE(strict.generate({start, {3, 0, 1}}, {0, 0}, at_rest(start), 0.0, field).ok);
}

TEST(Fallback, StopsAtEveryWaypointWithinTheLimits) {
  const std::vector<Eigen::Vector3d> pts{{0, 0, 0}, {1, 0, 0}, {1, 0.05, 0}, {3, 2, 1}};
  const FallbackSpline fb = make_fallback_spline(pts, Eigen::Vector3d::Zero(), 0.5, 2.0, 0.25);
  const Trajectory t = stops_at_every_point(fb, pts, 0);
  const Extremes e = sample_all(t);
  EXPECT_LE(e.speed, 0.5 * (1 + 1e-9));
  EXPECT_LE(e.acceleration, 2.0 * (1 + 1e-9));
}

TEST(Fallback, AMovingStartBrakesAlongItsVelocityThenReturnsToThePath) {
  // Descending at 0.9 m/s when a path up and sideways comes: the curve cannot start at rest.
  const std::vector<Eigen::Vector3d> pts{{0, 0, 1.5}, {1, -1, 2}, {2, -1, 2}};
  const Eigen::Vector3d v0(0, 0, -0.9);
  const double a = 2.0;
  const FallbackSpline fb = make_fallback_spline(pts, v0, 0.5, a, 0.25);
  const Trajectory t = stops_at_every_point(fb, pts, 1);
  const TrajectoryPoint p0 = t.sample(0.0);
  EXPECT_LT((p0.position - pts[0]).norm(), 1e-12);
  EXPECT_LT((p0.velocity - v0).norm(), 1e-12);
  const Extremes e = sample_all(t);
  EXPECT_LE(e.speed, 0.9 * (1 + 1e-9));
  EXPECT_LE(e.acceleration, a * (1 + 1e-9));
  // It goes as low as braking at the limit takes (0.9² / 2a = 0.2 m, plus at most one knot's
  // worth of the discrete ramp), straight below the start, and is otherwise on that ray or the path.
  double lowest = 1e300;
  for (double s = 0; s <= t.duration(); s += kSampleDt) {
    const Eigen::Vector3d p = t.position_at(s);
    lowest = std::min(lowest, p.z());
    const double off_ray = Eigen::Vector2d(p.x(), p.y()).norm();
    ASSERT_LT(std::min(off_ray, distance_to_polyline(pts, p)), 1e-9) << "off the ray and the path at " << s;
  }
  EXPECT_LT(lowest, 1.5 - 0.9 * 0.9 / (2 * a) + 1e-9);
  EXPECT_GT(lowest, 1.5 - 0.9 * 0.9 / (2 * a) - 0.9 * 0.25);
}

TEST(TrajectoryGeneration, AnOptimisedCurveThatStraysIsSlowedThenTakesTheFallback) {
  // deviation(): a curve on a line 0.3 m beside a straight path is 0.3 m from it.
  PositionSpline::Points q;
  for (int i = 0; i < 8; ++i) q.push_back(Eigen::Vector3d(0.5 * i, 0.3, 1.0));
  EXPECT_NEAR(TrajectoryGenerator::deviation(PositionSpline(q, 0.25), {{0, 0, 1}, {4, 0, 1}}), 0.3, 1e-9);
  EXPECT_NEAR(TrajectoryGenerator::deviation(PositionSpline(q, 0.25), {{0, 0.3, 1}, {4, 0.3, 1}}), 0.0, 1e-9);

  // A corner at 1 m/s: the optimiser rounds it, well within max_deviation...
  const std::vector<Eigen::Vector3d> corner = {{0, 0, 1}, {3, 0, 1}, {3, 3, 1}};
  ControllerConfig cfg;
  const GenerationResult smooth =
      TrajectoryGenerator(cfg).generate(corner, {0, 0, M_PI / 2}, at_rest(corner[0]), 0.0, FreeField());
  ASSERT_TRUE(smooth.ok) << smooth.reason;
  EXPECT_TRUE(smooth.trajectory.optimized) << smooth.reason;
  const double cut = TrajectoryGenerator::deviation(smooth.trajectory.position, corner);
  EXPECT_GT(cut, 0.0);
  EXPECT_LE(cut, cfg.trajectory.max_deviation);
  // ... not within a corridor narrower than that cut: then it is optimised again at the
  // fallback's cruise speed, cutting the corner far less...
  cfg.trajectory.max_deviation = 0.5 * cut;
  const GenerationResult slowed =
      TrajectoryGenerator(cfg).generate(corner, {0, 0, M_PI / 2}, at_rest(corner[0]), 0.0, FreeField());
  ASSERT_TRUE(slowed.ok) << slowed.reason;
  EXPECT_TRUE(slowed.trajectory.optimized);
  EXPECT_TRUE(slowed.slowed);
  EXPECT_NE(slowed.reason.find("strays"), std::string::npos) << slowed.reason;
  const double slow_cut = TrajectoryGenerator::deviation(slowed.trajectory.position, corner);
  EXPECT_GT(slow_cut, 0.0);
  EXPECT_LE(slow_cut, 0.5 * cut);
  // ... and within one narrower still, the fallback, on the path itself.
  cfg.trajectory.max_deviation = 0.5 * slow_cut;
  const GenerationResult strict =
      TrajectoryGenerator(cfg).generate(corner, {0, 0, M_PI / 2}, at_rest(corner[0]), 0.0, FreeField());
  ASSERT_TRUE(strict.ok) << strict.reason;
  EXPECT_FALSE(strict.trajectory.optimized);
  EXPECT_FALSE(strict.slowed);
  EXPECT_NE(strict.reason.find("strays"), std::string::npos) << strict.reason;
  EXPECT_LT(TrajectoryGenerator::deviation(strict.trajectory.position, corner), 1e-6);
  EXPECT_LT(slowed.trajectory.duration(), strict.trajectory.duration()) << "the slowed curve does not stop";
}

TEST(SlowZones, APolylineIsCutWhereItEntersAndLeavesAZone) {
  SlowZones z;
  EXPECT_TRUE(z.add({4, 0, 1}, 1.0));
  // A place within half a radius of a zone's centre grows that zone instead.
  EXPECT_FALSE(z.add({4.3, 0, 1}, 1.0));
  ASSERT_EQ(z.zones.size(), 1u);
  EXPECT_DOUBLE_EQ(z.zones[0].radius, 1.5);
  const SlowZones::Split s = z.split({{0, 0, 1}, {8, 0, 1}, {8, 4, 1}}, {0.0, 1.0, 2.0}, 0.5, 1.0);
  // The first leg in three pieces (x = 2.5 and 5.5), the second whole.
  ASSERT_EQ(s.points.size(), 5u);
  ASSERT_EQ(s.speed.size(), 4u);
  EXPECT_NEAR(s.points[1].x(), 2.5, 1e-9);
  EXPECT_NEAR(s.points[2].x(), 5.5, 1e-9);
  EXPECT_EQ(s.points[3], Eigen::Vector3d(8, 0, 1));
  EXPECT_EQ(s.speed, (std::vector<double>{1.0, 0.5, 1.0, 1.0}));
  // Headings keep their waypoints' and turn by length in between.
  EXPECT_NEAR(s.yaws[1], 2.5 / 8, 1e-9);
  EXPECT_NEAR(s.yaws[2], 5.5 / 8, 1e-9);
  EXPECT_EQ(s.yaws[3], 1.0);
  EXPECT_EQ(s.yaws[4], 2.0);
  // No zone: the polyline as it is, at full speed.
  const SlowZones::Split none = SlowZones{}.split({{0, 0, 1}, {8, 0, 1}}, {0.0, 1.0}, 0.5, 1.0);
  EXPECT_EQ(none.points.size(), 2u);
  EXPECT_EQ(none.speed, (std::vector<double>{1.0}));
}

TEST(TrajectoryGeneration, AFailingCornerOfALongPathIsSlowedThereOnly) {
  // Eight metres, a right angle, eight metres: the full-speed curve cuts the corner past a
  // max_deviation made narrower than its cut. Slowed near the corner only, the long legs are flown
  // at full speed; slowed along the whole path (slow_zone_radius 0), at half speed.
  const std::vector<Eigen::Vector3d> path = {{0, 0, 1}, {8, 0, 1}, {8, 8, 1}};
  const std::vector<double> yaws = {0, 0, M_PI / 2};
  ControllerConfig cfg;
  const GenerationResult fast =
      TrajectoryGenerator(cfg).generate(path, yaws, at_rest(path[0]), 0.0, FreeField());
  ASSERT_TRUE(fast.ok && fast.trajectory.optimized && !fast.slowed) << fast.reason;
  // 0.6 of its cut: the whole path at half speed cuts 0.51 of it, the corner alone slowed 0.39.
  cfg.trajectory.max_deviation = 0.6 * TrajectoryGenerator::deviation(fast.trajectory.position, path);
  const GenerationResult local =
      TrajectoryGenerator(cfg).generate(path, yaws, at_rest(path[0]), 0.0, FreeField());
  ASSERT_TRUE(local.ok) << local.reason;
  EXPECT_TRUE(local.trajectory.optimized);
  EXPECT_TRUE(local.slowed);
  EXPECT_EQ(local.slow_zones, 1) << local.reason;
  EXPECT_NE(local.reason.find("strays"), std::string::npos) << local.reason;
  EXPECT_LE(TrajectoryGenerator::deviation(local.trajectory.position, path), cfg.trajectory.max_deviation);
  cfg.trajectory.slow_zone_radius = 0.0;
  const GenerationResult whole =
      TrajectoryGenerator(cfg).generate(path, yaws, at_rest(path[0]), 0.0, FreeField());
  ASSERT_TRUE(whole.ok && whole.trajectory.optimized && whole.slowed) << whole.reason;
  EXPECT_EQ(whole.slow_zones, 0);
  // Fastest speed on the first leg, away from the corner.
  auto top_speed = [](const Trajectory& t) {
    double v = 0;
    for (double s = 0; s < t.duration(); s += 0.01)
      if (t.position_at(s).x() < 5.0) v = std::max(v, t.position.evaluate(s, 1).norm());
    return v;
  };
  EXPECT_GT(top_speed(local.trajectory), 0.9);
  EXPECT_LT(top_speed(whole.trajectory), 0.8);
  EXPECT_LT(local.trajectory.duration(), 0.75 * whole.trajectory.duration());
}

TEST(TrajectoryGeneration, TheFidelityTermKeepsTheFullSpeedCurveOnAZigzagPath) {
  // Three 1.5 m legs at right angles: smoothness alone rounds the zigzag 0.46 m off the path, past
  // max_deviation, and the curve is flown at half speed. Control points pay for offsets beyond
  // fidelity_tolerance from the initial curve, and the full-speed curve stays on the path.
  const std::vector<Eigen::Vector3d> zigzag = {{0, 0, 1}, {1.5, 0, 1}, {1.5, 1.5, 1}, {3, 1.5, 1}, {3, 0, 1}};
  const std::vector<double> yaws(zigzag.size(), 0.0);
  ControllerConfig cfg;
  cfg.optimizer.weight_fidelity = 20.0;
  const GenerationResult kept =
      TrajectoryGenerator(cfg).generate(zigzag, yaws, at_rest(zigzag[0]), 0.0, FreeField());
  ASSERT_TRUE(kept.ok) << kept.reason;
  EXPECT_TRUE(kept.trajectory.optimized);
  EXPECT_FALSE(kept.slowed) << kept.reason;
  EXPECT_LE(TrajectoryGenerator::deviation(kept.trajectory.position, zigzag), cfg.trajectory.max_deviation);

  cfg.optimizer.weight_fidelity = 0.0;
  cfg.trajectory.slow_zone_radius = 0.0;  // the whole path slowed, as when this rule came
  const GenerationResult loose =
      TrajectoryGenerator(cfg).generate(zigzag, yaws, at_rest(zigzag[0]), 0.0, FreeField());
  ASSERT_TRUE(loose.ok) << loose.reason;
  EXPECT_TRUE(loose.slowed);
  EXPECT_NE(loose.reason.find("strays"), std::string::npos) << loose.reason;
  EXPECT_LT(kept.trajectory.duration(), 0.7 * loose.trajectory.duration());
}

TEST(TrajectoryGeneration, OnlyOptimisedCurvesAnswerForTheTurnedBody) {
  // The fallback is the planner's own path (in a doorway, 0.35 m from the jambs in the ESDF, where
  // a body heading diagonally still fits the world): it keeps the plain bounds, and so does the
  // brake check while it is flown. An optimised curve is braked when its body would touch.
  ControllerConfig cfg;
  const TrajectoryGenerator gen(cfg);
  EXPECT_EQ(gen.generation_rule(true).footprint_half_xy, cfg.clearance.half_size);
  EXPECT_EQ(gen.generation_rule(true).footprint_half_z, cfg.clearance.half_height);
  EXPECT_EQ(gen.generation_rule(true).footprint_margin, cfg.clearance.footprint_margin);
  EXPECT_EQ(gen.generation_rule(false).footprint_half_xy, 0.0);
  EXPECT_EQ(gen.flight_rule(false).footprint_half_xy, 0.0);
  EXPECT_EQ(gen.flight_rule(true).footprint_half_xy, cfg.clearance.half_size);
  EXPECT_EQ(gen.flight_rule(true).footprint_margin, 0.0);
  cfg.clearance.turned_body = false;
  EXPECT_EQ(TrajectoryGenerator(cfg).generation_rule(true).footprint_half_xy, 0.0);

  // A straight path 0.36 m beside a post, heading 45° off the way: the path itself (the
  // fallback, exactly on it) is flown; its corner would reach 0.354 m toward the post. Its heading
  // is held square to the post where that keeps the corner off (square_fallback); where it cannot
  // (no repairs allowed), or with square_fallback off, it is flown as it is.
  cfg.clearance.turned_body = true;
  cfg.optimizer.max_iterations = 0;
  const std::vector<Eigen::Vector3d> line = {{0, 0, 1}, {4, 0, 1}};
  const PostField post(Eigen::Vector2d(2.0, 0.36));
  const ClearanceRule turned = TrajectoryGenerator(cfg).generation_rule(true);
  const GenerationResult held =
      TrajectoryGenerator(cfg).generate(line, {M_PI / 4, M_PI / 4}, at_rest(line[0]), 0.0, post);
  ASSERT_TRUE(held.ok) << held.reason;
  EXPECT_FALSE(held.trajectory.optimized);
  EXPECT_GE(held.repaired_headings, 1);
  EXPECT_TRUE(check_clearance(held.trajectory, post, 0, held.trajectory.duration(), turned).ok);
  for (const bool no_repairs : {true, false}) {
    ControllerConfig c = cfg;
    if (no_repairs)
      c.clearance.heading_repairs = 0;
    else
      c.clearance.square_fallback = false;
    const GenerationResult r =
        TrajectoryGenerator(c).generate(line, {M_PI / 4, M_PI / 4}, at_rest(line[0]), 0.0, post);
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_FALSE(r.trajectory.optimized);
    EXPECT_EQ(r.repaired_headings, 0);
    EXPECT_FALSE(check_clearance(r.trajectory, post, 0, r.trajectory.duration(), turned).ok)
        << "the same curve, had it been optimised, would not be flown";
  }
}
