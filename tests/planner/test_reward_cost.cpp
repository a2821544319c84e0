// The semantic reward at its boundary cases, the travel cost and the score ordering.
#include <gtest/gtest.h>

#include <cmath>

#include "semx/core/angles.hpp"
#include "semx/planner/semantic_reward.hpp"
#include "semx/planner/travel_cost.hpp"

namespace semx::planner {
namespace {

SemanticRegion region(const Eigen::Vector3d& p, double w, double r, bool active = true) {
  SemanticRegion s;
  s.centroid = p;
  s.weight = w;
  s.radius = r;
  s.active = active;
  return s;
}

TEST(SemanticReward, BoundaryCases) {
  const SemanticRegion s = region({1, 2, 1}, 30.0, 2.0);
  EXPECT_DOUBLE_EQ(region_reward({1, 2, 1}, s), 30.0);                                  // d = 0: w
  EXPECT_DOUBLE_EQ(region_reward({2, 2, 1}, s), 15.0);                                  // d = r/2: w/2
  EXPECT_NEAR(region_reward({3, 2, 1}, s), 0.0, 1e-12);                                 // d = r: 0
  EXPECT_DOUBLE_EQ(region_reward({3.0001, 2, 1}, s), 0.0);                              // d > r: 0
  EXPECT_DOUBLE_EQ(region_reward({1, 2, 40}, s), 0.0);                                  // far
  EXPECT_NEAR(region_reward({1 + 0.6, 2 + 0.8, 1}, s), 30.0 * (1 - 1.0 / 2.0), 1e-12);  // d = 1 diagonally
}

TEST(SemanticReward, InViewRewardsOnlyWhatTheNodesYawLooksAt) {
  const SemanticRegion s = region({1, 2, 1}, 30.0, 2.0);
  const Eigen::Vector3d node(2, 2, 1);  // 1 m east of the object: it lies at azimuth 180°
  const ViewCone west{core::kPi, 0.25 * core::kPi}, north{0.5 * core::kPi, 0.25 * core::kPi},
      edge{0.75 * core::kPi + 1e-9, 0.25 * core::kPi};
  EXPECT_DOUBLE_EQ(region_reward(node, s, &west), 15.0);
  EXPECT_DOUBLE_EQ(region_reward(node, s, &north), 0.0);  // looking away
  EXPECT_DOUBLE_EQ(region_reward(node, s, &edge), 15.0);  // at the edge of the 90° window
  EXPECT_DOUBLE_EQ(region_reward(node, s), 15.0);         // the paper's reward: no view
  const std::vector<SemanticRegion> both = {s, region({3, 2, 1}, 10.0, 2.0)};  // one each side
  EXPECT_DOUBLE_EQ(semantic_reward(node, both, nullptr, &west), 15.0);
  EXPECT_DOUBLE_EQ(semantic_reward(node, both), 20.0);
}

TEST(SemanticReward, SumsOverRegionsAndSkipsInactiveOnes) {
  const std::vector<SemanticRegion> regions{
      region({0, 0, 0}, 10.0, 1.0), region({1, 0, 0}, 20.0, 2.0),
      region({0.5, 0, 0}, 1000.0, 5.0, /*active=*/false),  // fully observed: attracts nothing
      region({9, 9, 9}, 10.0, 1.0),                        // out of reach
  };
  const Eigen::Vector3d p(0.5, 0, 0);
  EXPECT_DOUBLE_EQ(semantic_reward(p, regions), 10.0 * 0.5 + 20.0 * 0.75);
  EXPECT_DOUBLE_EQ(semantic_reward(p, {}), 0.0);
}

TEST(SemanticReward, MalformedRegionsRewardNothing) {
  const Eigen::Vector3d p(0, 0, 0);
  EXPECT_DOUBLE_EQ(region_reward(p, region(p, 10.0, 0.0)), 0.0);
  EXPECT_DOUBLE_EQ(region_reward(p, region(p, 10.0, -1.0)), 0.0);
  EXPECT_DOUBLE_EQ(region_reward(p, region(p, NAN, 1.0)), 0.0);
  EXPECT_DOUBLE_EQ(region_reward(p, region(p, -5.0, 1.0)), 0.0);
  EXPECT_DOUBLE_EQ(region_reward(p, region({NAN, 0, 0}, 10.0, 1.0)), 0.0);
}

TEST(TravelCost, DistanceOverSpeedPlusWeightedTurn) {
  CostConfig c;
  c.turn_while_flying = false;  // the paper's Eq. 8
  c.velocity = 2.0;
  c.yaw_rate = 0.5;
  c.yaw_weight = 3.0;
  c.min_time = 0.1;
  EXPECT_DOUBLE_EQ(travel_time(4.0, 0.0, c), 2.0);
  EXPECT_DOUBLE_EQ(travel_time(4.0, 1.0, c), 2.0 + 3.0 * 1.0 / 0.5);
  // The turn is the smaller way round: from 3 rad to -3 rad is 2π - 6.
  EXPECT_NEAR(travel_time(0.0, 3.0, -3.0, c), 3.0 * (2 * core::kPi - 6.0) / 0.5, 1e-12);
  EXPECT_NEAR(travel_time(0.0, -core::kPi + 0.1, core::kPi - 0.1, c), 3.0 * 0.2 / 0.5, 1e-12);
  // Floored so the node under the vehicle scores finitely.
  EXPECT_DOUBLE_EQ(travel_time(0.0, 0.0, c), 0.1);
}

TEST(TravelCost, TurningWhileFlyingTakesTheLongerOfTheTwo) {
  CostConfig c;  // the default
  ASSERT_TRUE(c.turn_while_flying);
  c.velocity = 2.0;
  c.yaw_rate = 0.5;
  c.yaw_weight = 3.0;
  c.min_time = 0.1;
  EXPECT_DOUBLE_EQ(travel_time(4.0, 0.0, c), 2.0);              // the flight alone
  EXPECT_DOUBLE_EQ(travel_time(4.0, 0.2, c), 2.0);              // a turn shorter than the flight is free
  EXPECT_DOUBLE_EQ(travel_time(4.0, 1.0, c), 3.0 * 1.0 / 0.5);  // a longer turn sets the time
  EXPECT_DOUBLE_EQ(travel_time(0.0, 1.0, c), 6.0);              // a turn in place as before
  EXPECT_DOUBLE_EQ(travel_time(0.0, 0.0, c), 0.1);
  // So a node that needs a move and a turn no longer loses to one that needs only the move.
  c.turn_while_flying = false;
  EXPECT_GT(travel_time(4.0, 0.2, c), travel_time(4.0, 0.0, c));
}

TEST(TravelCost, WrapAngle) {
  EXPECT_NEAR(core::wrap_angle(3 * core::kPi), core::kPi, 1e-12);
  EXPECT_NEAR(core::wrap_angle(-core::kPi), core::kPi, 1e-12);
  EXPECT_NEAR(core::wrap_angle(2 * core::kPi + 0.5), 0.5, 1e-12);
  EXPECT_NEAR(core::yaw_distance(0.1, -0.1), 0.2, 1e-12);
}

TEST(Score, OrdersByUtilityOverTime) {
  const CostConfig c;  // v = 1, ω = 1, w_psi = 1, turning while flying
  const double near_small = node_score(100, 0, travel_time(2.0, 0.0, c));  // 50
  const double far_big = node_score(300, 0, travel_time(10.0, 0.0, c));    // 30
  const double near_turn =
      node_score(100, 0, travel_time(2.0, core::kPi, c));  // 100 / π: the turn takes longer
  const double near_small_turn = node_score(100, 0, travel_time(2.0, 1.0, c));  // 50: turned on the way
  const double rewarded = node_score(100, 50, travel_time(2.0, 0.0, c));        // 75
  EXPECT_DOUBLE_EQ(near_small, 50.0);
  EXPECT_GT(near_small, far_big);
  EXPECT_GT(near_turn, far_big);
  EXPECT_DOUBLE_EQ(near_small_turn, near_small);
  EXPECT_GT(rewarded, near_small);
  EXPECT_NEAR(near_turn, 100.0 / core::kPi, 1e-12);
  // The paper's sum charges the turn on top of the flight.
  CostConfig sum;
  sum.turn_while_flying = false;
  EXPECT_NEAR(node_score(100, 0, travel_time(2.0, core::kPi, sum)), 100.0 / (2.0 + core::kPi), 1e-12);
  EXPECT_GT(far_big, node_score(100, 0, travel_time(2.0, core::kPi, sum)));
}

TEST(Score, ATimeExponentBelowOnePutsTheLargeGainFartherAwayFirst) {
  const CostConfig c;
  // e = 1 (the paper): 100 at 2 s (50) before 300 at 10 s (30); e = 0.5: 70.7 after 94.9.
  EXPECT_GT(node_score(100, 0, travel_time(2.0, 0.0, c), 1.0),
            node_score(300, 0, travel_time(10.0, 0.0, c), 1.0));
  EXPECT_NEAR(node_score(100, 0, 2.0, 0.5), 100.0 / std::sqrt(2.0), 1e-12);
  EXPECT_LT(node_score(100, 0, travel_time(2.0, 0.0, c), 0.5),
            node_score(300, 0, travel_time(10.0, 0.0, c), 0.5));
  EXPECT_EQ(node_score(100, 20, 3.0), node_score(100, 20, 3.0, 1.0));
}

}  // namespace
}  // namespace semx::planner
