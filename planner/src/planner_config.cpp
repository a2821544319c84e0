#include "semx/planner/planner_config.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace semx::planner {

const char* to_string(PlannerKind k) {
  switch (k) {
    case PlannerKind::kSemanticDep:
      return "semantic-dep";
    case PlannerKind::kDep:
      return "dep";
    case PlannerKind::kNbv:
      return "nbv";
    case PlannerKind::kAep:
      return "aep";
    case PlannerKind::kFuel:
      return "fuel";
    case PlannerKind::kOracle:
      return "oracle";
    case PlannerKind::kSemanticRoom:
      return "semantic-room";
    case PlannerKind::kSemanticFuel:
      return "semantic-fuel";
  }
  return "?";
}

PlannerKind parse_planner_kind(const std::string& name) {
  if (name == "semantic-dep") return PlannerKind::kSemanticDep;
  if (name == "dep") return PlannerKind::kDep;
  if (name == "nbv") return PlannerKind::kNbv;
  if (name == "aep") return PlannerKind::kAep;
  if (name == "fuel") return PlannerKind::kFuel;
  if (name == "oracle") return PlannerKind::kOracle;
  if (name == "semantic-room") return PlannerKind::kSemanticRoom;
  if (name == "semantic-fuel") return PlannerKind::kSemanticFuel;
  throw std::invalid_argument("unknown planner '" + name +
                              "' (semantic-dep, dep, nbv, aep, fuel, oracle, semantic-room, semantic-fuel)");
}

double GainConfig::horizontal_fov() const { return 2.0 * std::atan2(0.5 * image_width, fx); }
double GainConfig::vertical_fov() const { return 2.0 * std::atan2(0.5 * image_height, fy); }

namespace {

void get_vec3(runtime::ConfigMap& m, const std::string& key, Eigen::Vector3d& out, double lo, double hi) {
  std::vector<double> v{out.x(), out.y(), out.z()};
  m.get(key, v);
  if (v.size() != 3) m.fail(key, "expected 3 values");
  for (double x : v) {
    if (!(x >= lo && x <= hi))
      m.fail(key, "values must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  out = Eigen::Vector3d(v[0], v[1], v[2]);
}

}  // namespace

void load(runtime::ConfigMap& m, PlannerConfig& c) {
  m.get_choice("planner", c.planner,
               {"semantic-dep", "dep", "nbv", "aep", "fuel", "oracle", "semantic-room", "semantic-fuel"});
  m.get("seed", c.seed);
  m.get("rate_hz", c.rate_hz, 0.01, 1000.0);

  auto co = m.child("collision");
  get_vec3(co, "vehicle_size", c.collision.vehicle_size, 0.01, 10.0);
  co.get("margin", c.collision.margin, 0.0, 5.0);
  co.get("clearance", c.collision.clearance, 0.0, 5.0);
  co.get("passage_clearance", c.collision.passage_clearance, 0.0, 5.0);
  if (c.collision.passage_clearance > c.collision.clearance)
    co.fail("passage_clearance", "must not exceed clearance (passage points are where nodes fit too)");
  co.get("door_clearance", c.collision.door_clearance, 0.0, 5.0);
  if (c.collision.door_clearance > c.collision.passage_clearance)
    co.fail("door_clearance", "must not exceed passage_clearance");
  co.get("door_length", c.collision.door_length, 0.0, 100.0);
  co.get("edge_step", c.collision.edge_step, 0.005, 1.0);
  co.get("root_escape_radius", c.collision.root_escape_radius, 0.0, 5.0);

  auto s = m.child("sampling");
  s.get("samples", c.sampling.samples, 1, 100000);
  s.get("bridge_attempts", c.sampling.bridge_attempts, 0, 100000);
  s.get("max_attempts_factor", c.sampling.max_attempts_factor, 1, 1000);
  s.get("max_draws_factor", c.sampling.max_draws_factor, 1, 100000);
  s.get("local_radius", c.sampling.local_radius, 0.1, 100.0);
  s.get("local_height", c.sampling.local_height, 0.0, 100.0);
  s.get("frontier_fraction", c.sampling.frontier_fraction, 0.0, 1.0);
  s.get("frontier_radius", c.sampling.frontier_radius, 0.05, 100.0);
  s.get("min_node_distance", c.sampling.min_node_distance, 0.0, 100.0);
  s.get("z_min", c.sampling.z_min, -1000.0, 1000.0);
  s.get("z_max", c.sampling.z_max, -1000.0, 1000.0);
  s.get("cluster_size", c.sampling.cluster_size, 0.1, 100.0);
  s.get("min_cluster_voxels", c.sampling.min_cluster_voxels, 1, 1000000);
  if (!(c.sampling.z_min < c.sampling.z_max)) s.fail("z_max", "must be above z_min");

  auto r = m.child("roadmap");
  r.get("k_nearest", c.roadmap.k_nearest, 1, 1000);
  r.get("max_edge_length", c.roadmap.max_edge_length, 0.05, 100.0);

  auto g = m.child("gain");
  g.get("image_width", c.gain.image_width, 1, 100000);
  g.get("image_height", c.gain.image_height, 1, 100000);
  g.get("fx", c.gain.fx, 1e-3, 1e6);
  g.get("fy", c.gain.fy, 1e-3, 1e6);
  g.get("min_range", c.gain.min_range, 0.0, 100.0);
  g.get("max_range", c.gain.max_range, 0.05, 100.0);
  g.get("weight_unknown", c.gain.weight_unknown, 0.0, 1e6);
  g.get("weight_frontier", c.gain.weight_frontier, 0.0, 1e6);
  g.get("weight_surface", c.gain.weight_surface, 0.0, 1e6);
  g.get("yaw_bins", c.gain.yaw_bins, 1, 360);
  g.get("rays_azimuth", c.gain.rays_azimuth, 1, 100000);
  g.get("rays_elevation", c.gain.rays_elevation, 1, 100000);
  g.get("min_gain", c.gain.min_gain, 0.0, 1e12);
  g.get("sweep", c.gain.sweep);
  g.get("surface_occludes", c.gain.surface_occludes);
  if (!(c.gain.min_range < c.gain.max_range)) g.fail("max_range", "must be above min_range");
  if (c.gain.rays_azimuth % c.gain.yaw_bins != 0) g.fail("rays_azimuth", "must be a multiple of yaw_bins");

  auto k = m.child("cost");
  k.get("velocity", c.cost.velocity, 1e-3, 100.0);
  k.get("yaw_rate", c.cost.yaw_rate, 1e-3, 100.0);
  k.get("yaw_weight", c.cost.yaw_weight, 0.0, 1e6);
  k.get("min_time", c.cost.min_time, 1e-6, 1e6);
  k.get("time_exponent", c.cost.time_exponent, 0.0, 4.0);
  k.get("turn_while_flying", c.cost.turn_while_flying);
  k.get("local_first", c.cost.local_first, 0.0, 1e6);

  auto rw = m.child("reward");
  rw.get("unexplored_weight", c.reward.unexplored_weight, 0.0, 1e3);
  rw.get("passage_weight", c.reward.passage_weight, 0.0, 1e3);
  rw.get("in_view", c.reward.in_view);

  auto l = m.child("loop");
  l.get("goal_tolerance", c.loop.goal_tolerance, 0.0, 100.0);
  l.get("yaw_tolerance", c.loop.yaw_tolerance, 0.0, 7.0);
  l.get("dwell_s", c.loop.dwell_s, 0.0, 3600.0);
  l.get("short_hold_s", c.loop.short_hold_s, 0.0, 3600.0);
  l.get("lost_path_s", c.loop.lost_path_s, 0.0, 3600.0);
  l.get("hysteresis", c.loop.hysteresis, 1.0, 1e6);
  l.get("done_cycles", c.loop.done_cycles, 1, 1000000);
  l.get("max_recovery_cycles", c.loop.max_recovery_cycles, 1, 1000000);
  l.get("cut_looks", c.loop.cut_looks, 0, 1000);
  l.get("cut_look_cycles", c.loop.cut_look_cycles, 1, 1000000);
  l.get("cut_look_nodes", c.loop.cut_look_nodes, 1, 1000000);
  l.get("blacklist_cycles", c.loop.blacklist_cycles, 0, 1000000);
  l.get("visited_cycles", c.loop.visited_cycles, 0, 1000000);
  l.get("max_start_offset", c.loop.max_start_offset, 0.0, 100.0);
  l.get("yield_goals", c.loop.yield_goals, 0, 1000);
  l.get("end_game_gain", c.loop.end_game_gain, 0.0, 1e9);
  l.get("end_game_site_spacing", c.loop.end_game_site_spacing, 0.0, 100.0);
  l.get("end_game_max_sites", c.loop.end_game_max_sites, 1, 1000);
  l.get("pocket_detour", c.loop.pocket_detour, 0.0, 100.0);
  l.get("pocket_max_sites", c.loop.pocket_max_sites, 1, 16);
  l.get("pocket_left_behind", c.loop.pocket_left_behind);
  l.get("flying_refresh", c.loop.flying_refresh, 0, 1000000);

  auto ch = m.child("charge");
  ch.get("base_s", c.charge.base_s, 0.0, 1e3);
  ch.get("min_s", c.charge.min_s, 0.0, 1e3);
  ch.get("per_box_check_s", c.charge.per_box_check_s, 0.0, 1.0);
  ch.get("per_gain_node_s", c.charge.per_gain_node_s, 0.0, 1.0);
  ch.get("per_ray_step_s", c.charge.per_ray_step_s, 0.0, 1.0);
  ch.get("per_search_node_s", c.charge.per_search_node_s, 0.0, 1.0);
  ch.get("scale", c.charge.scale, 0.0, 1e6);

  auto n = m.child("nbv");
  n.get("step", c.nbv.step, 0.05, 100.0);
  n.get("lambda", c.nbv.lambda, 0.0, 100.0);
  n.get("radius", c.nbv.radius, 0.1, 100.0);

  auto a = m.child("aep");
  a.get("step", c.aep.step, 0.05, 100.0);
  a.get("rewire_radius", c.aep.rewire_radius, 0.0, 100.0);
  a.get("lambda", c.aep.lambda, 0.0, 100.0);
  a.get("radius", c.aep.radius, 0.1, 100.0);
  a.get("cache_radius", c.aep.cache_radius, 0.0, 100.0);
  a.get("g_zero", c.aep.g_zero, 0.0, 1e12);
  a.get("init_nodes", c.aep.init_nodes, 0, 100000);
  a.get("max_nodes", c.aep.max_nodes, 0, 100000);
  if (c.aep.max_nodes > 0 && c.aep.max_nodes < (c.aep.init_nodes > 0 ? c.aep.init_nodes : c.sampling.samples))
    a.fail("max_nodes", "must not be below init_nodes (sampling.samples when init_nodes is 0)");

  auto f = m.child("fuel");
  FuelConfig& fu = c.fuel;
  f.get("min_cluster_voxels", fu.min_cluster_voxels, 1, 1000000);
  f.get("major_cluster_voxels", fu.major_cluster_voxels, 1, 1000000000);
  f.get("major_coverage", fu.major_coverage, 0.0, 1e9);
  f.get("min_frontier_z", fu.min_frontier_z, -1000.0, 1000.0);
  f.get("split_radius", fu.split_radius, 0.1, 100.0);
  f.get("view_radius_min", fu.view_radius_min, 0.0, 100.0);
  f.get("view_radius_max", fu.view_radius_max, 0.0, 100.0);
  if (fu.view_radius_max < fu.view_radius_min) f.fail("view_radius_max", "must not be below view_radius_min");
  f.get("view_radius_steps", fu.view_radius_steps, 1, 100);
  f.get("view_angles", fu.view_angles, 1, 3600);
  f.get("view_height_step", fu.view_height_step, 0.0, 100.0);
  f.get("far_rings", fu.far_rings);
  f.get("approach", fu.approach);
  f.get("coverage_cells", fu.coverage_cells, 1, 100000);
  f.get("min_coverage", fu.min_coverage, 0.0, 1e9);
  f.get("min_view_distance", fu.min_view_distance, 0.0, 100.0);
  f.get("direction_weight", fu.direction_weight, 0.0, 100.0);
  f.get("refine_clusters", fu.refine_clusters, 1, 100);
  f.get("refine_radius", fu.refine_radius, 0.0, 1000.0);
  f.get("top_views", fu.top_views, 1, 10000);
  f.get("max_decay", fu.max_decay, 0.0, 1.0);
  f.get("exact_tour_max", fu.exact_tour_max, 0, 14);  // 2^14 x 14 states
  f.get("covered_fraction", fu.covered_fraction, 0.0, 1.0);
  f.get("replan_period", fu.replan_period, 0.0, 3600.0);
  f.get("switch_margin", fu.switch_margin, 0.0, 1.0);
  f.get("latency_tour", fu.latency_tour);
  f.get("latency_evaluations", fu.latency_evaluations, 1, 1000000);
  f.get("latency_gain", fu.latency_gain);
  f.get("latency_gain_power", fu.latency_gain_power, 0.1, 10.0);
  f.get("rate_first", fu.rate_first);
  f.get("latency_quota", fu.latency_quota, 0.0, 1.0);
  f.get("quota_weight", fu.quota_weight, 0.0, 1e6);
  f.get("square_clearance", fu.square_clearance, 0.0, 10.0);
  f.get("search_step", fu.search_step, 1, 8);
  f.get("low_clearance_penalty", fu.low_clearance_penalty, 0.0, 100.0);
  f.get("cost_budget", fu.cost_budget, 1000, 100000000);

  auto o = m.child("oracle");
  o.get("spacing", c.oracle.spacing, 0.05, 10.0);
  o.get("height_step", c.oracle.height_step, 0.05, 10.0);
  o.get("rays_azimuth", c.oracle.rays_azimuth, 8, 4096);
  o.get("rays_elevation", c.oracle.rays_elevation, 1, 1024);
  o.get("cover_fraction", c.oracle.cover_fraction, 0.0, 1.0);
  o.get("preferred_clearance", c.oracle.preferred_clearance, 0.0, 5.0);
  o.get("clearance_penalty", c.oracle.clearance_penalty, 0.0, 1e6);
  o.get("exact_tour_max", c.oracle.exact_tour_max, 0, 16);
  o.get("first_pass", c.oracle.first_pass, 0.0, 1.0);
  o.get("target_share", c.oracle.target_share, 0.0, 1.0);
  o.get("early_share", c.oracle.early_share, 0.0, 1.0);
  o.get("improve_evaluations", c.oracle.improve_evaluations, 0, 1000000);
  o.get("early_first_slack", c.oracle.early_first_slack, -1.0, 10.0);
  o.get("max_attempts", c.oracle.max_attempts, 1, 1000);
  o.get("needed_voxels", c.oracle.needed_voxels, 1, 1000000);
  o.get("chain", c.oracle.chain, 1, 1000);
  o.get("cache_mb", c.oracle.cache_mb, 0, 1 << 20);

  auto rm = m.child("room");
  rm.get("door_radius", c.room.door_radius, 0.0, 10.0);
  rm.get("passages_bound", c.room.passages_bound);
  rm.get("finish_gain", c.room.finish_gain, 0.0, 1e9);
  rm.get("eq6_reward", c.room.eq6_reward);
  rm.get("tour", c.room.tour);
  rm.get("boundary_gain", c.room.boundary_gain);
  rm.get("return_weight", c.room.return_weight, 0.0, 100.0);
  rm.get("cut_edges", c.room.cut_edges);
  rm.get("dead_ends_only", c.room.dead_ends_only);
  auto sf = m.child("semantic_fuel");
  sf.get("door_radius", c.semantic_fuel.door_radius, 0.0, 10.0);
  sf.get("door_height", c.semantic_fuel.door_height, 0.0, 10.0);
  sf.get("door_cost", c.semantic_fuel.door_cost, 0.0, 1e6);
  sf.get("object_pockets", c.semantic_fuel.object_pockets);
  sf.get("object_margin", c.semantic_fuel.object_margin, 0.0, 10.0);
  sf.get("object_reach", c.semantic_fuel.object_reach, 0.0, 1e3);
  sf.get("start_turns", c.semantic_fuel.start_turns, 0, 16);
  sf.get("doorway_first_cost", c.semantic_fuel.doorway_first_cost, 0.0, 1e6);
  sf.get("doorway_radius", c.semantic_fuel.doorway_radius, 0.0, 10.0);
  sf.get("door_clusters", c.semantic_fuel.door_clusters);
  sf.get("dep_first_s", c.semantic_fuel.dep_first_s, 0.0, 1e6);
  sf.get("tour_doors", c.semantic_fuel.tour_doors, 0, 1000);
  sf.get("greedy_ratio", c.semantic_fuel.greedy_ratio, 0.0, 1e6);
  sf.get("object_weight", c.semantic_fuel.object_weight, -1.0, 1e6);
  sf.get("door_weight", c.semantic_fuel.door_weight, 0.0, 1e6);
  sf.get("door_open_share", c.semantic_fuel.door_open_share, 0.0, 1.0);
  sf.get("door_probe_radius", c.semantic_fuel.door_probe_radius, 0.1, 10.0);
}

}  // namespace semx::planner
