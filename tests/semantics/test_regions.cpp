// Stage 4, reward bookkeeping: S_i = (p, l, w, r) from tracks, the paper's reward at its
// boundary cases, inactive regions, and when SEMANTIC_REGIONS is due.
#include <gtest/gtest.h>

#include "semx/semantics/regions.hpp"

using namespace semx::semantics;
using semx::runtime::SemanticClass;

namespace {

Track promoted(int64_t id, SemanticClass cls, const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  Track t;
  t.id = id;
  t.cls = cls;
  t.box = Eigen::AlignedBox3d(centre - size / 2, centre + size / 2);
  t.region = true;
  t.observations = 12;
  t.log_odds = 2.0;
  return t;
}

Region region_at(const Eigen::Vector3d& p, double w, double r) {
  Region g;
  g.centroid = p;
  g.weight = w;
  g.radius = r;
  return g;
}

}  // namespace

TEST(Reward, PaperFormulaAtItsBoundaries) {
  const Region g = region_at({1, 2, 1}, 300, 2.0);
  EXPECT_DOUBLE_EQ(reward(g, {1, 2, 1}), 300);              // d = 0: w
  EXPECT_DOUBLE_EQ(reward(g, {2, 2, 1}), 150);              // d = r/2: w/2
  EXPECT_DOUBLE_EQ(reward(g, {3, 2, 1}), 0);                // d = r: 0
  EXPECT_DOUBLE_EQ(reward(g, {3.01, 2, 1}), 0);             // d > r: 0
  EXPECT_NEAR(reward(g, {1, 2 + 1.2, 1 + 1.6}), 0, 1e-12);  // d = r along a diagonal
  Region off = g;
  off.active = false;
  EXPECT_DOUBLE_EQ(reward(off, {1, 2, 1}), 0);  // fully observed: nothing
  Region none = g;
  none.radius = 0;
  EXPECT_DOUBLE_EQ(reward(none, {1, 2, 1}), 0);
}

TEST(Reward, RegionsAddUp) {
  const std::vector<Region> rs = {region_at({0, 0, 0}, 100, 1), region_at({1, 0, 0}, 300, 2),
                                  region_at({10, 0, 0}, 1000, 1)};
  // At (0.5, 0, 0): 100 * 0.5 + 300 * 0.75; the far region adds nothing.
  EXPECT_DOUBLE_EQ(semantic_reward(rs, {0.5, 0, 0}), 50 + 225);
  EXPECT_DOUBLE_EQ(semantic_reward({}, {0, 0, 0}), 0);
}

TEST(Regions, WeightAndRadiusFromTheClassTableGrownByTheExtent) {
  RegionConfig c;
  std::vector<Track> tracks = {promoted(4, SemanticClass::kDoor, {1, 2, 1}, {0.9, 0.04, 2.0}),
                               promoted(2, SemanticClass::kChair, {3, 1, 0.45}, {0.4, 0.4, 0.9})};
  Track tentative = promoted(3, SemanticClass::kChair, {5, 1, 0.45}, {0.4, 0.4, 0.9});
  tentative.region = false;
  tracks.push_back(tentative);
  const auto rs = make_regions(tracks, c);
  ASSERT_EQ(rs.size(), 2u);  // tentative tracks are not regions
  EXPECT_EQ(rs[0].id, 2);    // ordered by id
  EXPECT_EQ(rs[0].cls, SemanticClass::kChair);
  EXPECT_DOUBLE_EQ(rs[0].weight, c.weight_scale * c.of(SemanticClass::kChair).weight);
  EXPECT_NEAR(rs[0].radius, 1.0 + 0.5 * std::sqrt(0.16 + 0.16 + 0.81), 1e-9);
  EXPECT_TRUE(rs[0].centroid.isApprox(Eigen::Vector3d(3, 1, 0.45)));
  EXPECT_TRUE(rs[0].extent.isApprox(Eigen::Vector3d(0.4, 0.4, 0.9)));
  EXPECT_EQ(rs[1].cls, SemanticClass::kDoor);
  EXPECT_GT(rs[1].weight, rs[0].weight);
  EXPECT_GT(rs[1].radius, rs[0].radius);
  EXPECT_NEAR(rs[1].confidence, 1.0 / (1.0 + std::exp(-2.0)), 1e-12);
  EXPECT_EQ(rs[1].observations, 12);

  // A class switched off in the config gives no region; a fully observed track an inactive one.
  c.classes[static_cast<std::size_t>(SemanticClass::kDoor)].enabled = false;
  tracks[1].fully_observed = true;
  tracks[1].observed_fraction = 0.9;
  const auto rs2 = make_regions(tracks, c);
  ASSERT_EQ(rs2.size(), 1u);
  EXPECT_FALSE(rs2[0].active);
  EXPECT_DOUBLE_EQ(rs2[0].observed_fraction, 0.9);
}

TEST(RegionPublisher, OnChangeAndEveryPeriodOfMessageTime) {
  RegionConfig c;
  RegionPublisher pub(c);
  std::vector<Region> rs = {region_at({1, 1, 1}, 100, 1)};
  rs[0].id = 1;
  EXPECT_TRUE(pub.due(rs, 1'000'000));   // the first set
  EXPECT_FALSE(pub.due(rs, 1'100'000));  // nothing new
  rs[0].centroid.x() += 0.03;            // below change_distance
  EXPECT_FALSE(pub.due(rs, 1'200'000));
  EXPECT_TRUE(pub.due(rs, 2'000'000));  // a period after the last publication
  EXPECT_FALSE(pub.due(rs, 2'500'000));
  rs[0].centroid.x() += 0.06;  // moved
  EXPECT_TRUE(pub.due(rs, 2'600'000));
  rs[0].active = false;  // fully observed
  EXPECT_TRUE(pub.due(rs, 2'700'000));
  rs[0].observed_fraction = 0.1;
  EXPECT_TRUE(pub.due(rs, 2'800'000));
  rs.push_back(region_at({3, 1, 1}, 100, 1));  // a new region
  rs[1].id = 2;
  EXPECT_TRUE(pub.due(rs, 2'900'000));
  rs.pop_back();  // one removed
  EXPECT_TRUE(pub.due(rs, 3'000'000));
  EXPECT_FALSE(pub.due(rs, 3'100'000));
  EXPECT_TRUE(pub.due(rs, 1'000));  // time went backwards: a new episode
  EXPECT_EQ(pub.published(), 8);
}
