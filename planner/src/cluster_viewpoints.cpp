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

namespace {

// The segment p-c crosses only free voxels, except next to c (within 1.5 voxels of its centre):
// FUEL tests the line of sight to its frontier cells, which are the free voxels beside the
// unknown ones; this frontier is the unknown side, and a ray that reaches the unknown voxel past
// the corner of another unknown voxel beside it still sees the free voxel in front of it.
bool sees(map::StateGrid::Reader& r, const map::KeyMath& km, const Eigen::Vector3d& p, const Eigen::Vector3d& c) {
  const double near2 = 2.25 * km.resolution() * km.resolution();
  return map::traverse_segment(km, p, c, [&](const VoxelKey& k) {
    const VoxelState s = r.state(k);
    if (s == VoxelState::kFree) return true;
    if (s == VoxelState::kOccupied) return false;
    return (km.center(k) - c).squaredNorm() <= near2;
  });
}

}  // namespace

Viewpoint ViewpointSampler::view_from(const map::StateGrid& grid, const std::vector<VoxelKey>& cells, double scale,
                                      const Eigen::Vector3d& p, int64_t* ray_steps) const {
  Viewpoint v;
  v.position = p;
  const map::KeyMath& km = grid.keys();
  NodeGain bins;
  bins.bin_gain.assign(static_cast<size_t>(gains_.bins()), 0.0f);
  bins.bin_count.assign(static_cast<size_t>(gains_.bins()), {0, 0, 0});
  int64_t steps = 0;
  map::StateGrid::Reader reader = grid.reader();
  for (const VoxelKey& k : cells) {
    const Eigen::Vector3d c = km.center(k);
    const Eigen::Vector3d d = c - p;
    if (!gains_.in_sector(d)) continue;
    steps += static_cast<int64_t>(d.norm() * km.inv_resolution()) + 1;
    if (!sees(reader, km, p, c)) continue;
    bins.bin_gain[static_cast<size_t>(gains_.bin_of(std::atan2(d.y(), d.x())))] += 1.0f;
  }
  if (ray_steps) *ray_steps += steps;
  gains_.finish(bins);
  v.yaw = bins.yaw;
  v.coverage = bins.gain * scale;
  return v;
}

std::vector<Viewpoint> ViewpointSampler::sample(const map::StateGrid& grid,
                                                const FrontierClusters::Cluster& cluster,
                                                CycleCounters* counters, double phase, bool far) const {
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
  std::vector<double> radii;
  for (int ri = 0; ri < fuel_.view_radius_steps; ++ri)
    radii.push_back(fuel_.view_radius_steps == 1
                        ? fuel_.view_radius_min
                        : fuel_.view_radius_min +
                              (fuel_.view_radius_max - fuel_.view_radius_min) * ri / (fuel_.view_radius_steps - 1));
  auto try_height = [&](double z) {
    z = std::clamp(z, sampling_.z_min, sampling_.z_max);
    for (const double r : radii) {
      for (int a = 0; a < fuel_.view_angles; ++a) {
        const double phi = -core::kPi + 2.0 * core::kPi * (a + phase) / fuel_.view_angles;
        const Eigen::Vector3d p(cluster.mean.x() + r * std::cos(phi), cluster.mean.y() + r * std::sin(phi), z);
        // One lookup rejects most candidates (inside walls, in unknown space) before the box check.
        if (grid.state(p) != VoxelState::kFree || !checker_.node_free(p)) continue;
        Viewpoint v = view_from(grid, cells, scale, p, &steps);
        if (v.coverage >= fuel_.min_coverage && v.coverage > 0) out.push_back(v);
      }
    }
  };
  auto try_heights = [&]() {
    try_height(cluster.mean.z());
    if (out.empty() && fuel_.view_height_step > 0) {
      // A cluster near the floor or the ceiling: its own height has no room for the vehicle.
      try_height(cluster.mean.z() + fuel_.view_height_step);
      try_height(cluster.mean.z() - fuel_.view_height_step);
    }
  };
  try_heights();
  if (out.empty()) {
    // Rings inside a small room: every candidate of FUEL's radii fell in the walls or the unknown
    // beyond them, and the cluster would stay without a viewpoint (dormant, in FUEL) while the
    // room is unexplored (env3, split_radius 1 m: DONE at 92.6 % with 24 such clusters).
    radii.clear();
    for (const double r : {0.5 * fuel_.view_radius_min, 0.25 * fuel_.view_radius_min})
      if (r > 0.1) radii.push_back(r);
    try_heights();
  }
  if (out.empty() && far && fuel_.view_radius_steps > 1) {
    // Rings beyond FUEL's, out to the camera's range: a cluster seen from afar through a doorway
    // has FUEL's rings all in the unknown room around it, and the known space it can be seen from
    // is farther.
    const double step = (fuel_.view_radius_max - fuel_.view_radius_min) / (fuel_.view_radius_steps - 1);
    radii.clear();
    if (step > 0)
      for (double r = fuel_.view_radius_max + step; r < gains_.config().max_range; r += step)
        radii.push_back(r);
    try_heights();
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Viewpoint& a, const Viewpoint& b) { return a.coverage > b.coverage; });
  // (The box checks are the checker's; its owner adds them to the cycle's counters.)
  if (counters) counters->ray_steps += steps;
  return out;
}

}  // namespace semx::planner
