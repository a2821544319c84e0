// MapperConfig: strict YAML loading and cross-field checks.
#include <gtest/gtest.h>

#include "semx/mapper/mapper.hpp"

namespace semx::mapper {
namespace {

MapperConfig load_yaml(const std::string& text) {
  runtime::ConfigMap m = runtime::ConfigMap::from_string(text, "test.yaml");
  MapperConfig c;
  load(m, c);
  m.finish();
  return c;
}

TEST(Config, DefaultsAreOctomapsAndThePapers) {
  const MapperConfig c = load_yaml("");
  EXPECT_DOUBLE_EQ(c.occupancy.resolution, 0.1);
  EXPECT_DOUBLE_EQ(c.occupancy.prob_hit, 0.7);
  EXPECT_DOUBLE_EQ(c.occupancy.prob_miss, 0.4);
  EXPECT_DOUBLE_EQ(c.occupancy.clamp_min, 0.1192);
  EXPECT_DOUBLE_EQ(c.occupancy.clamp_max, 0.971);
  EXPECT_DOUBLE_EQ(c.occupancy.threshold, 0.5);
  EXPECT_DOUBLE_EQ(c.occupancy.hold_range, 2.0);
  EXPECT_DOUBLE_EQ(c.integration.max_range, 5.0);
  EXPECT_EQ(c.integration.mode, IntegrationParams::Mode::kBundled);
  EXPECT_EQ(c.esdf.window, (std::vector<double>{10.0, 10.0, 3.0}));
  EXPECT_TRUE(c.esdf.unknown_as_occupied);
  EXPECT_NO_THROW(Mapper{c});
}

TEST(Config, ReadsEveryKey) {
  const MapperConfig c = load_yaml(R"(
resolution: 0.05
occupancy: {prob_hit: 0.8, prob_miss: 0.3, clamp_min: 0.12, clamp_max: 0.97, threshold: 0.6, hold_range: 0,
            bounds_min: [-10, -10, 0], bounds_max: [10, 10, 3]}
integration: {min_range: 0.3, max_range: 4.0, pixel_step: 2, mode: exact}
esdf: {enabled: false, window: [8, 8, 2], max_distance: 2.0, unknown_as_occupied: false}
streaming: {snapshot_period: 2.0, stats_period: 0.5, esdf_period: 0.1}
checkpoint: {path: /tmp/x.map, period: 60}
)");
  EXPECT_DOUBLE_EQ(c.occupancy.resolution, 0.05);
  EXPECT_DOUBLE_EQ(c.occupancy.threshold, 0.6);
  EXPECT_DOUBLE_EQ(c.occupancy.hold_range, 0.0);
  EXPECT_EQ(c.occupancy.bounds_max, (std::vector<double>{10, 10, 3}));
  EXPECT_EQ(c.integration.pixel_step, 2);
  EXPECT_EQ(c.integration.mode, IntegrationParams::Mode::kExact);
  EXPECT_FALSE(c.esdf.enabled);
  EXPECT_DOUBLE_EQ(c.streaming.esdf_period, 0.1);
  EXPECT_EQ(c.checkpoint.path, "/tmp/x.map");
}

void expect_error(const std::string& yaml, const std::string& fragment) {
  try {
    load_yaml(yaml);
    ADD_FAILURE() << "accepted: " << yaml;
  } catch (const runtime::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Config, RejectsTyposAndNonsense) {
  expect_error("resolushun: 0.1", "resolushun");
  expect_error("occupancy: {prob_hit: 0.4}", "prob_hit");
  expect_error("occupancy: {hold_range: -1}", "hold_range");
  expect_error("resolution: fast", "resolution");
  expect_error("occupancy: {clamp_min: 0.45, threshold: 0.4}", "clamp_min < threshold");
  expect_error("occupancy: {bounds_min: [0, 0, 0]}", "go together");
  expect_error("occupancy: {bounds_min: [0, 0, 0], bounds_max: [1, -1, 1]}", "below");
  expect_error("occupancy: {bounds_min: [-1e9, -1e9, 0], bounds_max: [1e9, 1e9, 3]}", "within ±3000 m");
  expect_error("integration: {min_range: 6}", "min_range");
  expect_error("integration: {mode: quick}", "not one of");
  expect_error("resolution: 0.01\nintegration: {max_range: 5}", "scratch");
  expect_error("esdf: {window: [10, 10]}", "3 numbers");
  expect_error("resolution: 0.02\nintegration: {max_range: 4}\nesdf: {window: [10, 10, 3]}", "8e6");
  MapperConfig bad;
  bad.occupancy.prob_miss = 0.6;
  EXPECT_THROW(Mapper{bad}, runtime::ConfigError);
  EXPECT_THROW(OccupancyMap{bad.occupancy}, runtime::ConfigError);
}

TEST(Config, AnOccupancyMapAloneNeedsOnlyItsOwnParameters) {
  // At 1 cm the mapper's default ESDF window and range would be too large, but a bare map
  // (e.g. a ground-truth grid) does not care.
  OccupancyParams p;
  p.resolution = 0.01;
  OccupancyMap map(p);
  map.update({1, 2, 3}, true);
  EXPECT_EQ(map.state(map::VoxelKey{1, 2, 3}), map::VoxelState::kOccupied);
}

}  // namespace
}  // namespace semx::mapper
