// Where candidate viewpoints are drawn (paper §III-D: "in the unexplored and traversable
// space"): a share of the draws uniformly in a box around the vehicle (the sensor's reach), the
// rest in boxes around frontier clusters anywhere in the map, so the roadmap grows toward every
// frontier, not only the nearest. The collision check then keeps only traversable, known-free
// draws; the gain decides which of them are worth flying to.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/planner/frontier_tracker.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

class Sampler {
 public:
  explicit Sampler(const SamplingConfig& config) : config_(config) {}

  // One draw. `frontier_fraction` overrides the configured share (recovery uses 1).
  Eigen::Vector3d draw(core::SplitMixRng& rng, const Eigen::Vector3d& vehicle,
                       const std::vector<FrontierTracker::Cluster>& clusters, double frontier_fraction,
                       bool* around_frontier = nullptr) const {
    const bool frontier = !clusters.empty() && rng.uniform() < frontier_fraction;
    if (around_frontier) *around_frontier = frontier;
    Eigen::Vector3d centre = vehicle;
    double half_xy = config_.local_radius, half_z = config_.local_height;
    if (frontier) {
      centre = clusters[static_cast<size_t>(rng.below(clusters.size()))].centre;
      half_xy = half_z = config_.frontier_radius;
    }
    // Heights: the box clipped to [z_min, z_max] (all of it when they do not overlap).
    double z_lo = std::max(centre.z() - half_z, config_.z_min),
           z_hi = std::min(centre.z() + half_z, config_.z_max);
    if (!(z_lo <= z_hi)) {
      z_lo = config_.z_min;
      z_hi = config_.z_max;
    }
    const double x = rng.uniform(centre.x() - half_xy, centre.x() + half_xy);
    const double y = rng.uniform(centre.y() - half_xy, centre.y() + half_xy);
    return {x, y, rng.uniform(z_lo, z_hi)};
  }

  const SamplingConfig& config() const { return config_; }

 private:
  SamplingConfig config_;
};

}  // namespace semx::planner
