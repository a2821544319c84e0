// Stage 4: semantic regions S_i = (p_i, l_i, w_i, r_i) from promoted tracks, the paper's reward
// R_i(n) = w_i (1 - d_i / r_i) for d_i <= r_i, and the rule for when SEMANTIC_REGIONS is due
// (on change, and at least every publish_period_s of message time).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/semantics/config.hpp"
#include "semx/semantics/tracker.hpp"

namespace semx::semantics {

struct Region {
  int64_t id = 0;  // the track's id: stable for the object's lifetime
  runtime::SemanticClass cls = runtime::SemanticClass::kNone;
  uint16_t instance = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // p_i
  double weight = 0.0;                                 // w_i
  double radius = 0.0;                                 // r_i
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  double confidence = 0.0;  // existence probability
  int observations = 0;
  double observed_fraction = 0.0;
  bool active = true;  // false once fully observed: rewards nothing
};

// w_i and r_i of an object of class `cls` whose box has `extent` (make_regions' rule; the planner's
// closed loop emulates regions with it).
double region_weight(const RegionConfig& config, runtime::SemanticClass cls);
double region_radius(const RegionConfig& config, runtime::SemanticClass cls, const Eigen::Vector3d& extent);

// The regions of the promoted tracks of enabled classes, ordered by id.
// w = weight_scale * classes[l].weight, r = classes[l].radius + radius_extent_gain * |extent| / 2.
std::vector<Region> make_regions(const std::vector<Track>& tracks, const RegionConfig& config);

// R_i(p): w (1 - d / r) within r of the centroid, else 0; 0 for inactive regions.
double reward(const Region& region, const Eigen::Vector3d& p);
// R_sem(p) = sum of R_i(p).
double semantic_reward(const std::vector<Region>& regions, const Eigen::Vector3d& p);

// Decides when the region set is published: when it differs from the last published set (a
// region added or removed, class, active flag or observation count crossing K changed, centroid
// or radius moved by more than change_distance, observed fraction by more than change_fraction),
// or publish_period_s of message time after the last publication. Time going backwards (a new
// episode) publishes at once.
class RegionPublisher {
 public:
  explicit RegionPublisher(const RegionConfig& config) : config_(config) {}
  // True when `regions` should be published at `utime`; then they become the last published.
  bool due(const std::vector<Region>& regions, int64_t utime);
  // True when `regions` differ from the last published set beyond the thresholds.
  bool changed(const std::vector<Region>& regions) const;
  int64_t published() const { return published_; }  // how many times due() said yes
  // When due() says yes next for unchanged regions (the periodic repeat); -1 before the first.
  int64_t next_repeat_utime() const;
  void reset();

 private:
  int64_t period_us() const;

  RegionConfig config_;
  std::vector<Region> last_;
  int64_t last_utime_ = -1;
  int64_t published_ = 0;
};

}  // namespace semx::semantics
