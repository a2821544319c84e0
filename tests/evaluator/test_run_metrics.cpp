// RunMetrics and Evaluation: Time_r at the 85 % boundary, distance integration, Time_f for each
// way a run ends, collisions, coverage samples, the end rules (due).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/evaluation.hpp"
#include "semx/evaluator/run_metrics.hpp"

namespace semx::evaluator {
namespace {

constexpr int64_t kS = 1000000;  // one second in utime

TEST(RunMetrics, TimeRIsTheFirstUpdateAtOrAbove85Percent) {
  RunMetrics m;
  m.on_coverage(1 * kS, 16, 20);  // 80 %
  EXPECT_FALSE(m.time_r_s());
  m.on_coverage(2 * kS, 17, 20);  // exactly 85 %: counts
  ASSERT_TRUE(m.time_r_s());
  EXPECT_DOUBLE_EQ(*m.time_r_s(), 2.0);
  m.on_coverage(3 * kS, 10, 20);  // a map that loses voxels does not move Time_r
  m.on_coverage(4 * kS, 19, 20);
  EXPECT_DOUBLE_EQ(*m.time_r_s(), 2.0);
  EXPECT_DOUBLE_EQ(m.coverage_pct(), 95.0);
}

TEST(RunMetrics, TimeRBoundaryOnALargeTargetSet) {
  const int64_t target = 136813;  // env1's |T| at 0.1 m
  const auto need = static_cast<int64_t>(std::ceil(0.85 * static_cast<double>(target)));
  RunMetrics m;
  m.on_coverage(5 * kS, need - 1, target);
  EXPECT_FALSE(m.time_r_s());
  m.on_coverage(5 * kS + 1, need, target);
  ASSERT_TRUE(m.time_r_s());
  EXPECT_DOUBLE_EQ(*m.time_r_s(), 5.000001);
}

TEST(RunMetrics, Time95AndTheEndGameFromACoverageSeries) {
  // 0 % to 96 % over 48 s (2 points a second), then 96.2 % at 60 s and 96.4 % at 100 s; DONE at
  // 150 s. Final 96.4 %: settled at the first update within 0.5 points (>= 95.9 %): 96 % at 48 s.
  RunMetrics m;
  for (int i = 0; i <= 48; ++i) m.on_coverage(i * kS, 20 * i, 1000);
  ASSERT_TRUE(m.time_95_s());
  EXPECT_DOUBLE_EQ(*m.time_95_s(), 48.0);  // 95.0 % is reached at 47.5 s, i.e. the 48 s update
  m.on_coverage(60 * kS, 962, 1000);
  m.on_coverage(100 * kS, 964, 1000);
  m.on_coverage(120 * kS, 964, 1000);  // no growth: does not move the settling time
  m.on_planner_state(150 * kS, PlannerState::kDone);
  m.finish(Termination::kPlannerDone, 151 * kS);
  ASSERT_TRUE(m.time_settled_s());
  EXPECT_DOUBLE_EQ(*m.time_settled_s(), 48.0);
  ASSERT_TRUE(m.end_game_s());
  EXPECT_DOUBLE_EQ(*m.end_game_s(), 150.0 - 48.0);
  EXPECT_DOUBLE_EQ(*m.time_95_s(), 48.0);
}

TEST(RunMetrics, A95ThatIsNeverReachedIsNullAndASettledRunHasNoEndGame) {
  RunMetrics none;
  EXPECT_FALSE(none.time_settled_s());  // no coverage heard
  EXPECT_FALSE(none.end_game_s());
  RunMetrics m;
  for (int i = 0; i <= 10; ++i) m.on_coverage(i * kS, 90 * i, 1000);  // up to 90 %, growing to the end
  m.finish(Termination::kTimeLimit, 10 * kS, 10.0);
  EXPECT_FALSE(m.time_95_s());
  ASSERT_TRUE(m.time_settled_s());
  EXPECT_DOUBLE_EQ(*m.time_settled_s(), 10.0);
  EXPECT_DOUBLE_EQ(*m.end_game_s(), 0.0);
}

TEST(RunMetrics, TimeRIsNullWhenNeverReached) {
  RunMetrics m;
  for (int i = 0; i <= 10; ++i) m.on_coverage(i * kS, 80 * i, 1000);  // up to 80 %
  m.finish(Termination::kTimeLimit, 10 * kS, 10.0);
  EXPECT_FALSE(m.time_r_s());
  EXPECT_NEAR(m.coverage_pct(), 80.0, 1e-12);
}

TEST(RunMetrics, CustomThreshold) {
  MetricsOptions o;
  o.coverage_threshold = 0.5;
  RunMetrics m(o);
  m.on_coverage(3 * kS, 50, 100);
  ASSERT_TRUE(m.time_r_s());
  EXPECT_DOUBLE_EQ(*m.time_r_s(), 3.0);
}

TEST(RunMetrics, TimeOIsTheFirstUpdateWithTheObjectsAt75Percent) {
  RunMetrics m;
  m.on_object_coverage(1000000, 70, 100);
  EXPECT_FALSE(m.time_o_s());
  EXPECT_DOUBLE_EQ(m.object_coverage_pct(), 70.0);
  m.on_object_coverage(2000000, 75, 100);
  m.on_object_coverage(3000000, 90, 100);
  ASSERT_TRUE(m.time_o_s());
  EXPECT_DOUBLE_EQ(*m.time_o_s(), 2.0);
  EXPECT_DOUBLE_EQ(m.object_coverage_pct(), 90.0);
  EXPECT_FALSE(m.time_r_s());  // the volume's threshold is the volume's
  RunMetrics none;
  none.on_object_coverage(1000000, 0, 0);  // a world without objects
  EXPECT_FALSE(none.time_o_s());
  EXPECT_DOUBLE_EQ(none.object_coverage_pct(), 0.0);
}

TEST(RunMetrics, DistanceIsIntegratedFromOdometry) {
  RunMetrics m;
  // A 2 x 1 m rectangle at 100 Hz, 1 cm per step: 6 m; then a duplicate, an old and a NaN message.
  int64_t t = 0;
  Eigen::Vector3d p(0, 0, 1);
  const Eigen::Vector3d dirs[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  const int steps[4] = {200, 100, 200, 100};
  m.on_odometry(t, p);
  for (int s = 0; s < 4; ++s) {
    for (int i = 0; i < steps[s]; ++i) {
      t += 10000;
      p += 0.01 * dirs[s];
      m.on_odometry(t, p);
    }
  }
  EXPECT_NEAR(m.distance_m(), 6.0, 1e-9);
  m.on_odometry(t, p + Eigen::Vector3d(5, 0, 0));     // same utime: ignored
  m.on_odometry(t - 5000, Eigen::Vector3d(9, 9, 9));  // older: ignored
  m.on_odometry(t + 10000, Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  EXPECT_NEAR(m.distance_m(), 6.0, 1e-9);
  m.on_odometry(t + 20000, p + Eigen::Vector3d(0, 0, 0.5));  // climbs 0.5 m
  EXPECT_NEAR(m.distance_m(), 6.5, 1e-9);
  // Trajectory kept for the picture: points at least 2 cm apart, first and corners included.
  ASSERT_GE(m.trajectory().size(), 250u);
  EXPECT_TRUE(m.trajectory().front().isApprox(Eigen::Vector3d(0, 0, 1)));
  m.finish(Termination::kStopped, t + 20000);
  m.on_odometry(t + 30000, Eigen::Vector3d(100, 0, 0));  // after the end: ignored
  EXPECT_NEAR(m.distance_m(), 6.5, 1e-9);
}

TEST(RunMetrics, TimeFForEachEnding) {
  {
    RunMetrics m;
    m.on_planner_state(40 * kS, PlannerState::kExecuting);
    m.on_planner_state(50 * kS, PlannerState::kDone);
    m.on_planner_state(51 * kS, PlannerState::kDone);  // a later DONE does not move it
    m.finish(Termination::kPlannerDone, 51 * kS + 10000);
    EXPECT_EQ(m.termination(), Termination::kPlannerDone);
    EXPECT_DOUBLE_EQ(m.time_f_s(), 50.0);
  }
  {
    RunMetrics m;
    m.advance(120 * kS + 5000);
    m.finish(Termination::kTimeLimit, 120 * kS + 5000, 120.0);
    EXPECT_DOUBLE_EQ(m.time_f_s(), 120.0);
  }
  {
    RunMetrics m;
    m.finish(Termination::kEpisodeEnd, 33 * kS);
    EXPECT_DOUBLE_EQ(m.time_f_s(), 33.0);
  }
  {
    RunMetrics m;
    m.on_odometry(7 * kS, Eigen::Vector3d::Zero());
    m.finish(Termination::kStopped, 0);
    EXPECT_DOUBLE_EQ(m.time_f_s(), 7.0);             // the last time seen
    m.finish(Termination::kTimeLimit, 9 * kS, 9.0);  // only the first end counts
    EXPECT_EQ(m.termination(), Termination::kStopped);
  }
}

TEST(RunMetrics, CollisionsCountEventsOrTheSimulatorsCountIfHigher) {
  RunMetrics m;
  EXPECT_EQ(m.collisions(), 0);
  m.on_collision(1 * kS, 1);
  m.on_collision(2 * kS, 2);
  EXPECT_EQ(m.collisions(), 2);
  m.on_collision(3 * kS, 5);  // the evaluator missed two
  EXPECT_EQ(m.collisions(), 5);
  EXPECT_EQ(m.collision_events(), 3);
}

TEST(RunMetrics, SamplesCoverageEveryPeriodAndAtTheEnd) {
  RunMetrics m;  // 1 s period
  for (int64_t t = 0; t <= 10 * kS; t += kS / 10) {
    m.on_coverage(t, t / (kS / 10), 1000);
    m.advance(t);
  }
  m.finish(Termination::kEpisodeEnd, 10 * kS + 500000);
  const auto& s = m.samples();
  ASSERT_EQ(s.size(), 12u);  // t = 0, 1, ..., 10 and the end
  for (int i = 0; i <= 10; ++i) {
    EXPECT_DOUBLE_EQ(s[i].t_s, i);
    EXPECT_NEAR(s[i].coverage_pct, i, 1e-9);  // 10 i voxels of 1000
  }
  EXPECT_DOUBLE_EQ(s.back().t_s, 10.5);
  EXPECT_EQ(s.back().covered, 100);
}

TEST(Evaluation, EndsAfterThePlannersDoneAndAtTheTimeLimit) {
  EvaluationOptions o;
  o.time_limit_s = 30;
  Evaluation ev(test::small_world(), o);
  EXPECT_FALSE(ev.due(29 * kS));
  EXPECT_EQ(ev.due(30 * kS), Termination::kTimeLimit);
  ev.on_planner_status(10 * kS, "dep", PlannerState::kDone, "no frontier left");
  EXPECT_EQ(ev.planner(), "dep");
  EXPECT_FALSE(ev.due(10 * kS));  // map updates up to the DONE are still to come
  EXPECT_EQ(ev.due(10 * kS + 1), Termination::kPlannerDone);
  ev.finish(Termination::kPlannerDone, 10 * kS + 10000, 2.0);
  EXPECT_TRUE(ev.finished());
  EXPECT_FALSE(ev.due(40 * kS));
  const RunSummary s = ev.summary();
  EXPECT_DOUBLE_EQ(s.time_f_s, 10.0);
  EXPECT_EQ(s.termination, "planner_done");
  EXPECT_EQ(s.planner_state, "DONE");
  EXPECT_EQ(s.planner_reason, "no frontier left");
  EXPECT_DOUBLE_EQ(s.wall_s, 2.0);
}

TEST(Evaluation, ALogThatEndsAfterDoneEndsWithDone) {
  Evaluation ev(test::small_world(), {});
  ev.on_planner_status(12 * kS, "", PlannerState::kDone);
  ev.finish(Termination::kLogEnd, 12 * kS, 0);
  EXPECT_EQ(ev.summary().termination, "planner_done");
  EXPECT_DOUBLE_EQ(ev.summary().time_f_s, 12.0);
}

TEST(Evaluation, CoverageFromDeltasAndTheGroundTruthFollowsTheMapsResolution) {
  EvaluationOptions o;
  o.resolution = 0.2;  // the map turns out to be at 0.1 m
  Evaluation ev(test::small_world(), o);
  const simulator::GroundTruth gt(test::small_world(), 0.1);
  const auto deltas = test::sweep_deltas(gt, 5, kS, kS);  // the 4th is empty
  map::StateGrid grid(0.1);
  for (const auto& d : deltas) {
    for (const auto& c : d.changes) grid.set_state(c.key, c.state);
    ev.on_map_delta(d, grid);
    EXPECT_EQ(ev.tracker().covered(), CoverageTracker::count_covered(ev.ground_truth(), grid));
  }
  EXPECT_DOUBLE_EQ(ev.tracker().resolution(), 0.1);
  EXPECT_DOUBLE_EQ(ev.metrics().coverage_pct(), 100.0);
  ASSERT_TRUE(ev.metrics().time_r_s());
  EXPECT_DOUBLE_EQ(*ev.metrics().time_r_s(), 5.0);  // only the last delta reaches 85 %
  EXPECT_EQ(ev.map_deltas(), 5);
}

}  // namespace
}  // namespace semx::evaluator
