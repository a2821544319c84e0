// Viewpoints of a frontier cluster (FUEL, Zhou et al. 2021, §IV-B; FrontierFinder::
// sampleViewpoints and countVisibleCells): candidates on circles around the cluster's mean, kept
// when the vehicle can hover there (CollisionChecker::node_free: the clearance of DEP's goals)
// and they see enough of the cluster, each with the yaw that sees the most of it.
//
// A candidate sees a cluster voxel when the voxel is in the sensor model's range and vertical
// field of view (GainEvaluator::in_sector, the camera every planner here uses) and the segment to
// it crosses only known free voxels up to the voxel's own surroundings (FUEL: neither occupied nor
// unknown ones; the gain's optimistic rule would count voxels behind unknown space that the
// camera does not see). The
// seen voxels go to the gain's azimuth bins; the viewpoint's yaw is the centre of the window of
// bins that holds the most (GainEvaluator::finish: among ties the middle of the first run), and
// its coverage is that count, scaled from the tested voxels (at most fuel.coverage_cells, spread
// over the cluster) to the whole cluster.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "semx/map/state_grid.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/frontier_clusters.hpp"
#include "semx/planner/gain_evaluator.hpp"
#include "semx/planner/plan_types.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

struct Viewpoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  double coverage = 0.0;  // cluster voxels seen (scaled)
};

class ViewpointSampler {
 public:
  ViewpointSampler(const PlannerConfig& config, const CollisionChecker& checker, const GainEvaluator& gains);

  // The cluster's viewpoints, best coverage first (ties: candidate order); empty when none sees
  // min_coverage voxels. The rings' directions start `phase` (0..1) of their spacing past -pi.
  // With `far`, when no ring of FUEL's radii (nor at a half and a quarter of the least) has a
  // viewpoint, rings farther out in the same steps to the camera's range are tried too.
  // Counts its ray steps into `counters`.
  std::vector<Viewpoint> sample(const map::StateGrid& grid, const FrontierClusters::Cluster& cluster,
                                CycleCounters* counters, double phase = 0.0, bool far = false) const;
  // The coverage and yaw from one position (tests; sample() uses it for every candidate).
  Viewpoint view_from(const map::StateGrid& grid, const std::vector<map::VoxelKey>& cells, double scale,
                      const Eigen::Vector3d& p, int64_t* ray_steps) const;

 private:
  FuelConfig fuel_;
  SamplingConfig sampling_;
  const CollisionChecker& checker_;
  const GainEvaluator& gains_;
};

}  // namespace semx::planner
