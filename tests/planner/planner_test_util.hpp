// Helpers for the planner's tests: hand-made voxel scenes and planner configurations.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/fixtures/synthetic_world.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/frontier_tracker.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/planner/strategy.hpp"

namespace semx::planner {

// Sets every voxel of the inclusive key box to s.
inline void fill(map::StateGrid& g, const map::VoxelKey& lo, const map::VoxelKey& hi, map::VoxelState s) {
  for (int32_t z = lo.z; z <= hi.z; ++z)
    for (int32_t y = lo.y; y <= hi.y; ++y)
      for (int32_t x = lo.x; x <= hi.x; ++x) g.set_state({x, y, z}, s);
}

// Sets the voxels whose centres lie in the box [lo, hi] (metres) to s.
inline void fill_m(map::StateGrid& g, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                   map::VoxelState s) {
  const map::KeyMath& km = g.keys();
  const double r = km.resolution();
  const map::VoxelKey a = km.key(lo + Eigen::Vector3d::Constant(0.5 * r - 1e-9));
  const map::VoxelKey b = km.key(hi - Eigen::Vector3d::Constant(0.5 * r - 1e-9));
  fill(g, a, b, s);
}

// A test configuration: the defaults, fewer gain rays (tests run many evaluations).
inline PlannerConfig test_config(const std::string& planner = "semantic-dep") {
  PlannerConfig c;
  c.planner = planner;
  c.gain.rays_azimuth = 64;
  c.gain.rays_elevation = 8;
  return c;
}

// What a strategy's plan() reads besides the strategy itself, for scenes built by hand: the map,
// its frontiers, the regions, the random numbers and the counters, and a context pointing at them.
struct PlanScene {
  explicit PlanScene(const std::string& planner, uint64_t seed = 1)
      : config(test_config(planner)), rng(seed) {}
  PlannerConfig config;
  map::StateGrid grid = map::StateGrid(0.1);
  FrontierTracker frontiers{1.0};
  core::SplitMixRng rng;
  std::vector<SemanticRegion> regions;
  CycleCounters counters;

  PlanContext context(const Eigen::Vector3d& p, double yaw = 0.0, int64_t cycle = 1) {
    PlanContext ctx;
    ctx.grid = &grid;
    ctx.pose.position = p;
    ctx.pose.yaw = yaw;
    ctx.regions = &regions;
    ctx.frontiers = &frontiers;
    ctx.cycle = cycle;
    ctx.rng = &rng;
    ctx.counters = &counters;
    return ctx;
  }
};

}  // namespace semx::planner
