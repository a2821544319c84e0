// The accuracy evaluation in small: the scoring rules, the survey paths, and a short stretch of
// the env2 survey with the detection and depth noise models on.
#include <gtest/gtest.h>

#include "semantics_sim.hpp"

using namespace semx::semantics;
using semx::runtime::SemanticClass;

TEST(Accuracy, MatchingIsOneToOneWithinTheDistanceAndByClass) {
  AccuracyReport rep;
  auto object = [](SemanticClass c, uint16_t id, const Eigen::Vector3d& p) {
    semx::simulator::ObjectInfo o;
    o.cls = c;
    o.instance = id;
    o.center = p;
    return o;
  };
  rep.objects = {object(SemanticClass::kChair, 1, {0, 0, 0}), object(SemanticClass::kChair, 2, {1, 0, 0}),
                 object(SemanticClass::kTable, 3, {5, 0, 0}), object(SemanticClass::kSofa, 4, {9, 0, 0})};
  rep.longest_view_s = {2.0, 2.0, 2.0, 0.5};  // the sofa was never in view for a second
  auto region = [](SemanticClass c, const Eigen::Vector3d& p) {
    Region r;
    r.cls = c;
    r.centroid = p;
    return r;
  };
  const std::vector<Region> regions = {
      region(SemanticClass::kChair, {0.1, 0, 0}),   // chair 1, 0.1 m off
      region(SemanticClass::kChair, {0.05, 0, 0}),  // a duplicate of chair 1: false positive
      region(SemanticClass::kTv, {5, 0, 0}),        // wrong class at the table: false positive
      region(SemanticClass::kSofa, {9.2, 0, 0}),    // the sofa (counts for precision only)
  };
  score_regions(regions, rep, 0.5, 1.0);
  EXPECT_EQ(rep.total.regions, 4);
  EXPECT_EQ(rep.total.true_regions, 2);
  EXPECT_DOUBLE_EQ(rep.total.precision(), 0.5);
  EXPECT_EQ(rep.total.objects_in_view, 3);                                    // chairs and table
  EXPECT_EQ(rep.total.found, 1);                                              // chair 1 only
  EXPECT_NEAR(rep.classes[SemanticClass::kChair].error_mean(), 0.05, 1e-12);  // nearest pair wins
  EXPECT_NEAR(rep.total.error_mean(), (0.05 + 0.2) / 2, 1e-12);
  EXPECT_EQ(rep.matches[2].object, -1);
}

TEST(Accuracy, TheFirstSecondsOfTheEnv2SurveyUnderNoise) {
  AccuracyOptions opt;
  opt.max_seconds = 12.0;  // the first full turn in room A
  const AccuracyReport r = run_accuracy(opt, SemanticsConfig{});
  EXPECT_GT(r.frames, 300);
  EXPECT_GE(r.total.objects_in_view, 8);
  EXPECT_GE(r.total.precision(), 0.95);
  EXPECT_GE(r.total.recall(), 0.9);
  // From one place, objects behind others are seen in part and their boxes are short: the
  // centroid error is larger than over the whole survey (0.04 m, docs/semantics.md).
  EXPECT_LE(r.total.error_mean(), 0.2);
}

TEST(Accuracy, SurveyPathsStayInTheWorld) {
  const auto world = semx::simulator::load_world(semx::simulator::shipped_world_path("env1"));
  const auto stops = survey_stops(world);
  ASSERT_GT(stops.size(), 5u);
  for (std::size_t i = 0; i < stops.size(); ++i) {
    EXPECT_TRUE(stops[i].spin);
    EXPECT_EQ(stops[i].jump, i > 0);
    EXPECT_TRUE(world.bounds.contains(stops[i].position));
  }
  // Turning at 0.6 rad/s at 30 Hz: a full turn is 2π / 0.6 s; jumps add one pose each.
  const auto poses = sample_path(stops, 0.0, 0.5, 0.6, 30.0);
  const double turn_frames = std::ceil(2 * M_PI / (0.6 / 30.0));
  EXPECT_EQ(poses.size(), 1 + stops.size() * static_cast<std::size_t>(turn_frames) + (stops.size() - 1));
  // The env2 survey flies between its stops at 0.5 m/s: consecutive poses at most 1.7 cm apart.
  const auto flown = sample_path(env2_survey_path(), 0.0, 0.5, 0.6, 30.0);
  for (std::size_t i = 1; i < flown.size(); ++i) {
    EXPECT_LE((flown[i].position - flown[i - 1].position).norm(), 0.5 / 30.0 + 1e-9);
  }
}
