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

// semx-evaluator's journal: an evaluator killed mid-run and restored from the records it had
// saved (one per coverage sample), then fed the map's snapshot and the rest of the run, ends with
// the figures, series and trajectory of the one that was never killed.
TEST(Evaluation, RestoredFromItsJournalItEndsAsTheUndisturbedOne) {
  const simulator::GroundTruth gt(test::small_world(), 0.1);
  const auto deltas = test::sweep_deltas(gt, 20, kS / 2, kS / 2);
  Evaluation a(test::small_world(), {});
  std::vector<std::vector<uint8_t>> journal;
  Evaluation::Saved saved;
  map::StateGrid grid(0.1), grid_b(0.1);
  size_t next_delta = 0;
  // One run's events up to `until` (utime), fed to `e`; `grid` follows the deltas.
  auto feed = [&](Evaluation& e, map::StateGrid& grid, int64_t from, int64_t until, bool save) {
    for (int64_t t = from; t < until; t += kS / 10) {
      const double x = 0.3 * static_cast<double>(t) / kS;
      e.on_odometry(t, Eigen::Vector3d(x, std::sin(x), 1.0));
      if (next_delta < deltas.size() && deltas[next_delta].utime <= t) {
        for (const auto& c : deltas[next_delta].changes) grid.set_state(c.key, c.state);
        e.on_map_delta(deltas[next_delta++], grid);
      }
      if (t == 3 * kS) e.on_collision(t, 1);
      if (t == 4 * kS) e.on_node_status("mapper", 100, 0, t);
      if (t == 5 * kS) e.on_planner_status(t, "dep", PlannerState::kExecuting);
      const size_t before = e.metrics().samples().size();
      e.advance(t);
      if (save && e.metrics().samples().size() != before) {
        std::vector<uint8_t> rec;
        core::ByteWriter w(rec);
        e.save(w, saved);
        journal.push_back(std::move(rec));
      }
    }
  };
  feed(a, grid, 0, 6 * kS + kS / 10, true);
  // The crash: b is a new evaluator that reads the journal back, then hears the mapper's snapshot.
  Evaluation b(test::small_world(), {});
  for (const auto& rec : journal) {
    core::ByteReader r(rec.data(), rec.size());
    b.restore(r);
    EXPECT_EQ(r.remaining(), 0u);
  }
  EXPECT_EQ(b.metrics().samples().size(), a.metrics().samples().size());
  EXPECT_DOUBLE_EQ(b.metrics().distance_m(), a.metrics().distance_m());
  for (size_t i = 0; i < next_delta; ++i)
    for (const auto& c : deltas[i].changes) grid_b.set_state(c.key, c.state);
  b.on_map_reset(grid_b, 6 * kS + kS / 10, deltas[next_delta - 1].seq);
  EXPECT_EQ(b.tracker().covered(), a.tracker().covered());
  b.on_node_status("mapper", 200, 1, 7 * kS);  // the mapper came back too
  a.on_node_status("mapper", 200, 1, 7 * kS);
  // The rest of the run, to both.
  const size_t resume_delta = next_delta;
  feed(a, grid, 6 * kS + kS / 10, 12 * kS, false);
  next_delta = resume_delta;
  feed(b, grid_b, 6 * kS + kS / 10, 12 * kS, false);
  a.on_planner_status(12 * kS, "dep", PlannerState::kDone);
  b.on_planner_status(12 * kS, "dep", PlannerState::kDone);
  a.finish(Termination::kStopped, 12 * kS, 3.0);
  b.finish(Termination::kStopped, 12 * kS, 3.0);
  const RunSummary sa = a.summary(), sb = b.summary();
  EXPECT_EQ(sb.termination, "planner_done");
  EXPECT_EQ(sb.info.planner, "dep");
  EXPECT_DOUBLE_EQ(sb.time_f_s, sa.time_f_s);
  EXPECT_DOUBLE_EQ(sb.distance_m, sa.distance_m);
  EXPECT_DOUBLE_EQ(sb.coverage_pct, sa.coverage_pct);
  EXPECT_EQ(sb.time_r_s, sa.time_r_s);
  EXPECT_EQ(sb.time_95_s, sa.time_95_s);
  EXPECT_EQ(sb.time_settled_s, sa.time_settled_s);
  EXPECT_EQ(sb.time_o_s, sa.time_o_s);
  EXPECT_EQ(sb.collisions, 1);
  ASSERT_EQ(sb.coverage.size(), sa.coverage.size());
  for (size_t i = 0; i < sa.coverage.size(); ++i) {
    EXPECT_DOUBLE_EQ(sb.coverage[i].t_s, sa.coverage[i].t_s);
    EXPECT_DOUBLE_EQ(sb.coverage[i].coverage_pct, sa.coverage[i].coverage_pct) << i;
    EXPECT_DOUBLE_EQ(sb.coverage[i].distance_m, sa.coverage[i].distance_m) << i;
  }
  EXPECT_EQ(sb.trajectory, sa.trajectory);
  ASSERT_EQ(sb.restarts.size(), 1u);
  EXPECT_EQ(sb.restarts[0].node, "mapper");
  EXPECT_DOUBLE_EQ(sb.restarts[0].t_s, 7.0);
  EXPECT_EQ(sb.restarts[0].restarts, 1);
}

TEST(Evaluation, ANodeThatComesBackMarksTheRunDisturbed) {
  Evaluation ev(test::small_world(), {});
  ev.on_node_status("mapper", 10, 0, 1 * kS);
  ev.on_node_status("mapper", 10, 0, 2 * kS);
  ev.on_node_status("planner", 11, 0, 2 * kS);
  EXPECT_TRUE(ev.restarts().empty()) << "the same processes, heard again";
  ev.on_node_status("mapper", 12, 1, 3 * kS);     // respawned by the launcher
  ev.on_node_status("planner", 13, 0, 4 * kS);    // another pid without a launcher restart
  ev.on_node_status("semantics", 14, 2, 5 * kS);  // first heard after two restarts
  const RunSummary s = ev.summary();
  ASSERT_EQ(s.restarts.size(), 3u);
  EXPECT_EQ(s.restarts[0].node, "mapper");
  EXPECT_DOUBLE_EQ(s.restarts[0].t_s, 3.0);
  EXPECT_EQ(s.restarts[1].node, "planner");
  EXPECT_EQ(s.restarts[1].restarts, 0);
  EXPECT_EQ(s.restarts[2].restarts, 2);
}

}  // namespace
}  // namespace semx::evaluator
