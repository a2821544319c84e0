// The semantics configuration: defaults, the documented YAML file, strictness.
#include <gtest/gtest.h>

#include "semx/semantics/config.hpp"

using namespace semx::semantics;
using semx::runtime::ConfigError;
using semx::runtime::load_config;
using semx::runtime::SemanticClass;

TEST(SemanticsConfig, TheShippedYamlIsExactlyTheDefaults) {
  const SemanticsConfig d;
  const auto f =
      load_config<SemanticsConfig>(std::string(SEMX_SOURCE_DIR) + "/semantics/config/semantics.yaml");
#define SAME(field) EXPECT_EQ(f.field, d.field) << #field
  SAME(detector.type);
  SAME(detector.use_instances);
  SAME(detector.min_area_px);
  SAME(detector.morph_kernel_px);
  SAME(detector.frame_period_s);
  SAME(detector.latency_s);
  SAME(detector.dnn.model);
  SAME(detector.dnn.input_width);
  SAME(detector.dnn.input_height);
  SAME(detector.dnn.scale);
  SAME(detector.dnn.mean);
  SAME(detector.dnn.swap_rb);
  SAME(detector.dnn.classes);
  SAME(detector.dnn.min_score);
  SAME(lift.max_pixel_stride);
  SAME(lift.voxel_size);
  SAME(lift.outlier_neighbours);
  SAME(lift.outlier_stddev);
  SAME(lift.cluster_tolerance);
  SAME(lift.min_points);
  SAME(tracking.gate_distance);
  SAME(tracking.min_observations);
  SAME(tracking.min_duration_s);
  SAME(tracking.promote_probability);
  SAME(tracking.log_odds_hit);
  SAME(tracking.log_odds_miss);
  SAME(tracking.region_log_odds_miss);
  SAME(tracking.log_odds_max);
  SAME(tracking.drop_log_odds);
  SAME(tracking.tentative_timeout_s);
  SAME(tracking.voxel_min_observations);
  SAME(tracking.voxel_min_fraction);
  SAME(tracking.merge_overlap);
  SAME(tracking.confusion_ratio);
  SAME(tracking.face_cell);
  SAME(tracking.free_probe);
  SAME(tracking.fully_observed_fraction);
  SAME(tracking.min_known_fraction);
  SAME(regions.weight_scale);
  SAME(regions.radius_extent_gain);
  SAME(regions.publish_period_s);
  SAME(regions.change_distance);
  SAME(regions.change_fraction);
#undef SAME
  for (std::size_t i = 0; i < kClassCount; ++i) {
    SCOPED_TRACE(semx::runtime::kSemanticClasses[i].name);
    EXPECT_EQ(f.regions.classes[i].enabled, d.regions.classes[i].enabled);
    EXPECT_EQ(f.regions.classes[i].weight, d.regions.classes[i].weight);
    EXPECT_EQ(f.regions.classes[i].radius, d.regions.classes[i].radius);
  }
}

TEST(SemanticsConfig, DefaultsRewardDoorsMostAndNeverTheBuilding) {
  const RegionConfig r;
  for (std::size_t i = 0; i < kClassCount; ++i) {
    const auto& info = semx::runtime::kSemanticClasses[i];
    SCOPED_TRACE(info.name);
    EXPECT_EQ(r.classes[i].enabled, !info.structural);
    if (info.id != SemanticClass::kDoor) {
      EXPECT_LT(r.classes[i].weight, r.of(SemanticClass::kDoor).weight);
    }
  }
}

TEST(SemanticsConfig, OverridesAndClassTable) {
  const auto c = load_config<SemanticsConfig>(
      "", {"tracking.min_observations=8", "regions.classes.chair.weight=2.5",
           "regions.classes.lamp.enabled=false", "detector.use_instances=false"});
  EXPECT_EQ(c.tracking.min_observations, 8);
  EXPECT_EQ(c.regions.of(SemanticClass::kChair).weight, 2.5);
  EXPECT_EQ(c.regions.of(SemanticClass::kChair).radius, 1.0);  // untouched key keeps its default
  EXPECT_FALSE(c.regions.of(SemanticClass::kLamp).enabled);
  EXPECT_FALSE(c.detector.use_instances);
}

TEST(SemanticsConfig, RejectsWhatWouldSilentlyGiveWrongFigures) {
  auto fails = [](const std::vector<std::string>& o, const std::string& needle) {
    try {
      load_config<SemanticsConfig>("", o);
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(fails({"tracking.min_observaitons=3"}, "unknown key"));
  EXPECT_TRUE(fails({"regions.classes.planet.weight=1"}, "unknown key"));
  EXPECT_TRUE(fails({"regions.classes.wall.enabled=true"}, "part of the building"));
  EXPECT_TRUE(fails({"detector.morph_kernel_px=4"}, "odd"));
  EXPECT_TRUE(fails({"detector.type=yolo"}, "type"));
  EXPECT_TRUE(fails({"detector.type=dnn"}, "ONNX"));
  EXPECT_TRUE(fails({"detector.dnn.classes=[chair, planet]"}, "planet"));
  EXPECT_TRUE(fails({"lift.voxel_size=0.2"}, "cluster_tolerance"));
  EXPECT_TRUE(fails({"tracking.promote_probability=1.5"}, "outside"));
}
