// The planner's configuration: the shipped YAML equals the defaults; overrides; strictness.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "semx/planner/planner_config.hpp"

namespace semx::planner {
namespace {

using runtime::ConfigError;
using runtime::load_config;

TEST(PlannerConfig, TheShippedYamlIsExactlyTheDefaults) {
  const PlannerConfig d;
  const auto f = load_config<PlannerConfig>(std::string(SEMX_SOURCE_DIR) + "/planner/config/planner.yaml");
#define SAME(field) EXPECT_EQ(f.field, d.field) << #field
  SAME(planner);
  SAME(seed);
  SAME(rate_hz);
  SAME(collision.vehicle_size);
  SAME(collision.margin);
  SAME(collision.clearance);
  SAME(collision.passage_clearance);
  SAME(collision.edge_step);
  SAME(collision.root_escape_radius);
  SAME(sampling.samples);
  SAME(sampling.bridge_attempts);
  SAME(sampling.max_attempts_factor);
  SAME(sampling.max_draws_factor);
  SAME(sampling.local_radius);
  SAME(sampling.local_height);
  SAME(sampling.frontier_fraction);
  SAME(sampling.frontier_radius);
  SAME(sampling.min_node_distance);
  SAME(sampling.z_min);
  SAME(sampling.z_max);
  SAME(sampling.cluster_size);
  SAME(sampling.min_cluster_voxels);
  SAME(roadmap.k_nearest);
  SAME(roadmap.max_edge_length);
  SAME(gain.image_width);
  SAME(gain.image_height);
  SAME(gain.fx);
  SAME(gain.fy);
  SAME(gain.min_range);
  SAME(gain.max_range);
  SAME(gain.weight_unknown);
  SAME(gain.weight_frontier);
  SAME(gain.weight_surface);
  SAME(gain.yaw_bins);
  SAME(gain.rays_azimuth);
  SAME(gain.rays_elevation);
  SAME(gain.min_gain);
  SAME(cost.velocity);
  SAME(cost.yaw_rate);
  SAME(cost.yaw_weight);
  SAME(cost.min_time);
  SAME(cost.turn_while_flying);
  SAME(reward.unexplored_weight);
  SAME(reward.passage_weight);
  SAME(loop.goal_tolerance);
  SAME(loop.yaw_tolerance);
  SAME(loop.dwell_s);
  SAME(loop.short_hold_s);
  SAME(loop.hysteresis);
  SAME(loop.done_cycles);
  SAME(loop.max_recovery_cycles);
  SAME(loop.cut_looks);
  SAME(loop.cut_look_cycles);
  SAME(loop.cut_look_nodes);
  SAME(loop.blacklist_cycles);
  SAME(loop.visited_cycles);
  SAME(loop.max_start_offset);
  SAME(charge.base_s);
  SAME(charge.min_s);
  SAME(charge.per_box_check_s);
  SAME(charge.per_gain_node_s);
  SAME(charge.per_ray_step_s);
  SAME(charge.per_search_node_s);
  SAME(charge.scale);
  SAME(nbv.step);
  SAME(nbv.lambda);
  SAME(nbv.radius);
  SAME(aep.step);
  SAME(aep.rewire_radius);
  SAME(aep.lambda);
  SAME(aep.radius);
  SAME(aep.cache_radius);
  SAME(aep.g_zero);
  SAME(aep.init_nodes);
  SAME(aep.max_nodes);
  SAME(fuel.min_cluster_voxels);
  SAME(fuel.major_cluster_voxels);
  SAME(fuel.major_coverage);
  SAME(fuel.min_frontier_z);
  SAME(fuel.split_radius);
  SAME(fuel.view_radius_min);
  SAME(fuel.view_radius_max);
  SAME(fuel.view_radius_steps);
  SAME(fuel.view_angles);
  SAME(fuel.view_height_step);
  SAME(fuel.far_rings);
  SAME(fuel.approach);
  SAME(fuel.coverage_cells);
  SAME(fuel.min_coverage);
  SAME(fuel.min_view_distance);
  SAME(fuel.direction_weight);
  SAME(fuel.refine_clusters);
  SAME(fuel.refine_radius);
  SAME(fuel.top_views);
  SAME(fuel.max_decay);
  SAME(fuel.exact_tour_max);
  SAME(fuel.covered_fraction);
  SAME(fuel.replan_period);
  SAME(fuel.switch_margin);
  SAME(fuel.latency_tour);
  SAME(fuel.latency_evaluations);
  SAME(fuel.latency_gain);
  SAME(fuel.latency_gain_power);
  SAME(fuel.rate_first);
  SAME(fuel.search_step);
  SAME(fuel.low_clearance_penalty);
  SAME(fuel.cost_budget);
  SAME(fuel.square_clearance);
  SAME(semantic_fuel.object_pockets);
  SAME(semantic_fuel.object_margin);
  SAME(semantic_fuel.object_reach);
  SAME(semantic_fuel.door_radius);
  SAME(semantic_fuel.door_height);
  SAME(semantic_fuel.door_cost);
  SAME(semantic_fuel.start_turns);
  SAME(semantic_fuel.doorway_first_cost);
  SAME(semantic_fuel.doorway_radius);
  SAME(semantic_fuel.dep_first_s);
  SAME(semantic_fuel.greedy_ratio);
  SAME(semantic_fuel.object_weight);
  SAME(semantic_fuel.door_weight);
  SAME(semantic_fuel.door_open_share);
  SAME(semantic_fuel.door_probe_radius);
#undef SAME
}

TEST(PlannerConfig, DefaultsMatchThePaperAndTheController) {
  const PlannerConfig d;
  EXPECT_EQ(d.sampling.samples, 45);
  EXPECT_EQ(d.gain.weight_unknown, 1.0);
  EXPECT_EQ(d.gain.weight_frontier, 2.0);
  EXPECT_EQ(d.gain.weight_surface, 4.0);
  EXPECT_EQ(d.gain.yaw_bins, 32);
  EXPECT_NEAR(d.gain.horizontal_fov(), 3.14159265358979 / 2, 1e-12);
  EXPECT_NEAR(d.gain.vertical_fov(), 2 * std::atan(0.75), 1e-12);
  // Every edge point keeps the controller's bound (half_size 0.25 + margin 0.07) plus the pad of
  // its dense check (half a 0.02 m step times the field's Lipschitz bound, sqrt(3)), in the same
  // ESDF units, in doorways; elsewhere the body's half diagonal (0.354 m) plus that pad
  // (test_clearance_consistency.cpp checks it against the real field).
  EXPECT_GE(d.collision.door_clearance, 0.32 + 0.5 * std::sqrt(3.0) * 0.02 - 1e-12);
  EXPECT_GE(d.collision.passage_clearance, 0.354 + 0.5 * std::sqrt(3.0) * 0.02);
  EXPECT_LE(d.collision.door_clearance, d.collision.passage_clearance);
  EXPECT_LE(d.collision.passage_clearance, d.collision.clearance);
  EXPECT_EQ(d.kind(), PlannerKind::kSemanticDep);
}

TEST(PlannerConfig, TheShippedAblationsLoad) {
  const std::string dir = std::string(SEMX_SOURCE_DIR) + "/planner/config/ablations/";
  EXPECT_FALSE(load_config<PlannerConfig>(dir + "paper_travel_cost.yaml").cost.turn_while_flying);
  EXPECT_EQ(load_config<PlannerConfig>(dir + "unexplored_weight_0.001.yaml").reward.unexplored_weight, 0.001);
  EXPECT_EQ(load_config<PlannerConfig>(dir + "unexplored_weight_0.003.yaml").reward.unexplored_weight, 0.003);
  EXPECT_EQ(load_config<PlannerConfig>(dir + "passage_weight_0.001.yaml").reward.passage_weight, 0.001);
  EXPECT_EQ(load_config<PlannerConfig>(dir + "passage_weight_0.0003.yaml").reward.passage_weight, 0.0003);
  const PlannerConfig tour = load_config<PlannerConfig>(dir + "fuel_latency_tour.yaml");
  EXPECT_TRUE(tour.fuel.latency_tour);
  EXPECT_FALSE(tour.fuel.latency_gain);
  const PlannerConfig gain = load_config<PlannerConfig>(dir + "fuel_latency_gain.yaml");
  EXPECT_TRUE(gain.fuel.latency_tour && gain.fuel.latency_gain);
  EXPECT_TRUE(gain.semantic_fuel.object_pockets);
  const PlannerConfig no_pockets = load_config<PlannerConfig>(dir + "fuel_latency_gain_no_pockets.yaml");
  EXPECT_TRUE(no_pockets.fuel.latency_tour && no_pockets.fuel.latency_gain);
  EXPECT_FALSE(no_pockets.semantic_fuel.object_pockets);
  // Every file there is one a bench can be given (`--arg planner_config=...`).
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    EXPECT_NO_THROW(load_config<PlannerConfig>(entry.path().string())) << entry.path();
  }
  EXPECT_GE(files, 8);  // the eight read above, at least
}

TEST(PlannerConfig, OverridesAndErrors) {
  const auto c =
      load_config<PlannerConfig>("", {"planner=aep", "sampling.samples=30", "gain.weight_surface=8"});
  EXPECT_EQ(c.kind(), PlannerKind::kAep);
  EXPECT_EQ(c.sampling.samples, 30);
  EXPECT_EQ(c.gain.weight_surface, 8.0);
  EXPECT_EQ(load_config<PlannerConfig>("", {"reward.unexplored_weight=0.002"}).reward.unexplored_weight,
            0.002);
  EXPECT_THROW(load_config<PlannerConfig>("", {"reward.unexplored_weight=-1"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"reward.passage_weight=-1"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"planner=rrt"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"sampling.sample=30"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"sampling.samples=0"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"gain.rays_azimuth=100"}),
               ConfigError);                                                          // not a multiple of 32
  EXPECT_THROW(load_config<PlannerConfig>("", {"gain.max_range=0.2"}), ConfigError);  // below min_range
  EXPECT_THROW(load_config<PlannerConfig>("", {"collision.vehicle_size=[1, 2]"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"aep.init_nodes=20", "aep.max_nodes=10"}), ConfigError);
  EXPECT_THROW(load_config<PlannerConfig>("", {"aep.max_nodes=30"}), ConfigError);  // below samples (45)
  EXPECT_NO_THROW(load_config<PlannerConfig>("", {"aep.init_nodes=15", "aep.max_nodes=30"}));
  EXPECT_THROW(parse_planner_kind("DEP"), std::invalid_argument);
  EXPECT_THROW(load_config<PlannerConfig>("", {"fuel.view_radius_max=1.0"}), ConfigError);  // below min
  EXPECT_EQ(load_config<PlannerConfig>("", {"planner=fuel"}).kind(), PlannerKind::kFuel);
  EXPECT_EQ(load_config<PlannerConfig>("", {"planner=semantic-fuel"}).kind(), PlannerKind::kSemanticFuel);
  for (const char* name : {"semantic-dep", "dep", "nbv", "aep", "fuel"})
    EXPECT_STREQ(to_string(parse_planner_kind(name)), name);
}

}  // namespace
}  // namespace semx::planner
