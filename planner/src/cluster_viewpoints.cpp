#include "semx/planner/cluster_viewpoints.hpp"

#include <algorithm>
#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

ViewpointSampler::ViewpointSampler(const PlannerConfig& config, const CollisionChecker& checker,
                                   const GainEvaluator& gains)
    : fuel_(config.fuel), sampling_(config.sampling), checker_(checker), gains_(gains) {}

Viewpoint ViewpointSampler::view_from(const map::StateGrid& grid, const std::vector<VoxelKey>& cells, double scale,
                                      const Eigen::Vector3d& p, int64_t* ray_steps) const {
  Viewpoint v;
  v.position = p;
  const map::KeyMath& km = grid.keys();
  NodeGain bins;
  bins.bin_gain.assign(static_cast<size_t>(gains_.bins()), 0.0f);
  bins.bin_count.assign(static_cast<size_t>(gains_.bins()), {0, 0, 0});
  int64_t steps = 0;
  for (const VoxelKey& k : cells) {
    const Eigen::Vector3d c = km.center(k);
    const Eigen::Vector3d d = c - p;
    if (!gains_.in_sector(d)) continue;
    steps += static_cast<int64_t>(d.norm() * km.inv_resolution()) + 1;
    if (!grid.is_visible(p, c, true)) continue;
    bins.bin_gain[static_cast<size_t>(gains_.bin_of(std::atan2(d.y(), d.x())))] += 1.0f;
  }
  if (ray_steps) *ray_steps += steps;
  gains_.finish(bins);
  v.yaw = bins.yaw;
  v.coverage = bins.gain * scale;
  return v;
}

std::vector<Viewpoint> ViewpointSampler::sample(const map::StateGrid& grid, const FrontierClusters::Cluster& cluster,
                                                CycleCounters* counters) const {
  std::vector<Viewpoint> out;
  if (cluster.voxels.empty()) return out;
  // The voxels tested for visibility: every n-th in key order, which spreads them over the cluster.
  const size_t n = cluster.voxels.size();
  const size_t stride = std::max<size_t>(1, (n + static_cast<size_t>(fuel_.coverage_cells) - 1) /
                                                static_cast<size_t>(fuel_.coverage_cells));
  std::vector<VoxelKey> cells;
  for (size_t i = 0; i < n; i += stride) cells.push_back(cluster.voxels[i]);
  const double scale = static_cast<double>(n) / static_cast<double>(cells.size());
  int64_t steps = 0;
  auto try_height = [&](double z) {
    z = std::clamp(z, sampling_.z_min, sampling_.z_max);
    const int rings = fuel_.view_radius_steps;
    for (int ri = 0; ri < rings; ++ri) {
      const double r = rings == 1 ? fuel_.view_radius_min
                                  : fuel_.view_radius_min +
                                        (fuel_.view_radius_max - fuel_.view_radius_min) * ri / (rings - 1);
      for (int a = 0; a < fuel_.view_angles; ++a) {
        const double phi = -core::kPi + 2.0 * core::kPi * a / fuel_.view_angles;
        const Eigen::Vector3d p(cluster.mean.x() + r * std::cos(phi), cluster.mean.y() + r * std::sin(phi), z);
        // One lookup rejects most candidates (inside walls, in unknown space) before the box check.
        if (grid.state(p) != VoxelState::kFree || !checker_.node_free(p)) continue;
        Viewpoint v = view_from(grid, cells, scale, p, &steps);
        if (v.coverage >= fuel_.min_coverage && v.coverage > 0) out.push_back(v);
      }
    }
  };
  try_height(cluster.mean.z());
  if (out.empty() && fuel_.view_height_step > 0) {
    // A cluster near the floor or the ceiling: its own height has no room for the vehicle.
    try_height(cluster.mean.z() + fuel_.view_height_step);
    try_height(cluster.mean.z() - fuel_.view_height_step);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Viewpoint& a, const Viewpoint& b) { return a.coverage > b.coverage; });
  // (The box checks are the checker's; its owner adds them to the cycle's counters.)
  if (counters) counters->ray_steps += steps;
  return out;
}

}  // namespace semx::planner
