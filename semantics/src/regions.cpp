#include "semx/semantics/regions.hpp"

#include <algorithm>
#include <cmath>

namespace semx::semantics {

double region_weight(const RegionConfig& config, runtime::SemanticClass cls) {
  return config.weight_scale * config.of(cls).weight;
}

double region_radius(const RegionConfig& config, runtime::SemanticClass cls, const Eigen::Vector3d& extent) {
  return config.of(cls).radius + config.radius_extent_gain * 0.5 * extent.norm();
}

std::vector<Region> make_regions(const std::vector<Track>& tracks, const RegionConfig& config) {
  std::vector<Region> out;
  for (const Track& t : tracks) {
    if (!t.region || t.box.isEmpty()) continue;
    const ClassParams& p = config.of(t.cls);
    if (!p.enabled) continue;
    Region r;
    r.id = t.id;
    r.cls = t.cls;
    r.instance = t.instance;
    r.centroid = t.centroid();
    r.extent = t.extent();
    r.weight = region_weight(config, t.cls);
    r.radius = region_radius(config, t.cls, r.extent);
    r.confidence = t.probability();
    r.observations = t.observations;
    r.observed_fraction = t.observed_fraction;
    r.active = !t.fully_observed;
    out.push_back(r);
  }
  std::sort(out.begin(), out.end(), [](const Region& a, const Region& b) { return a.id < b.id; });
  return out;
}

double reward(const Region& region, const Eigen::Vector3d& p) {
  if (!region.active || !(region.radius > 0)) return 0.0;
  const double d = (p - region.centroid).norm();
  if (!(d <= region.radius)) return 0.0;
  return region.weight * (1.0 - d / region.radius);
}

double semantic_reward(const std::vector<Region>& regions, const Eigen::Vector3d& p) {
  double sum = 0;
  for (const auto& r : regions) sum += reward(r, p);
  return sum;
}

bool RegionPublisher::changed(const std::vector<Region>& regions) const {
  if (regions.size() != last_.size()) return true;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const Region& a = regions[i];
    const Region& b = last_[i];
    if (a.id != b.id || a.cls != b.cls || a.active != b.active || a.instance != b.instance) return true;
    if ((a.centroid - b.centroid).norm() > config_.change_distance) return true;
    if (std::abs(a.radius - b.radius) > config_.change_distance) return true;
    if (std::abs(a.observed_fraction - b.observed_fraction) > config_.change_fraction) return true;
  }
  return false;
}

bool RegionPublisher::due(const std::vector<Region>& regions, int64_t utime) {
  const int64_t period = period_us();
  const bool first = last_utime_ < 0 || utime < last_utime_;
  if (!first && !changed(regions) && utime - last_utime_ < period) return false;
  last_ = regions;
  last_utime_ = utime;
  ++published_;
  return true;
}

int64_t RegionPublisher::next_repeat_utime() const {
  if (last_utime_ < 0) return -1;
  return last_utime_ + period_us();
}

int64_t RegionPublisher::period_us() const {
  return static_cast<int64_t>(std::llround(config_.publish_period_s * 1e6));
}

void RegionPublisher::reset() {
  last_.clear();
  last_utime_ = -1;
}

}  // namespace semx::semantics
