#include "semx/mapper/occupancy_map.hpp"

#include <algorithm>
#include <cmath>

namespace semx::mapper {

namespace {
// OctoMap's octomap::logodds(): computed in double, stored as float.
float logit(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }
}  // namespace

OccupancyMap::OccupancyMap(const OccupancyParams& params)
    : params_(params),
      grid_(params.resolution, /*with_log_odds=*/true),
      l_hit_(logit(params.prob_hit)),
      l_miss_(logit(params.prob_miss)),
      l_min_(logit(params.clamp_min)),
      l_max_(logit(params.clamp_max)),
      l_occ_(logit(params.threshold)),
      hold_(params.hold_range > 0.0) {
  validate(params);
  if (!params.bounds_min.empty()) {
    bounded_ = true;
    const double inv = grid_.keys().inv_resolution();
    for (int i = 0; i < 3; ++i) {
      // Voxel k is inside when its centre (k + 0.5) * res is.
      bounds_.min[i] = static_cast<int32_t>(std::ceil(params.bounds_min[i] * inv - 0.5));
      bounds_.max[i] = static_cast<int32_t>(std::floor(params.bounds_max[i] * inv - 0.5));
    }
  }
}

std::optional<float> OccupancyMap::log_odds(const map::VoxelKey& k) const {
  const map::VoxelBlock* b = grid_.find_block(map::block_of(k));
  if (!b) return std::nullopt;
  const int i = map::local_index(k);
  if (b->state[i] == map::VoxelState::kUnknown) return std::nullopt;
  return b->log_odds[i];
}

bool OccupancyMap::is_held(const map::VoxelKey& k) const {
  const std::optional<float> l = log_odds(k);
  return l && *l == kHeld;
}

map::VoxelState OccupancyMap::update(const map::VoxelKey& k, bool hit, bool* changed, bool near) {
  if (!in_bounds(k)) {
    if (changed) *changed = false;
    return grid_.state(k);
  }
  map::VoxelBlock& b = grid_.get_or_create_block(map::block_of(k));
  map::VoxelState before, after;
  apply(b, k, map::local_index(k), hit, near, before, after);
  if (changed) *changed = before != after;
  return after;
}

void OccupancyMap::set_log_odds(const map::VoxelKey& k, float log_odds) {
  if (std::isnan(log_odds)) {
    grid_.set_state(k, map::VoxelState::kUnknown);
    return;
  }
  map::VoxelBlock& b = grid_.get_or_create_block(map::block_of(k));
  const int i = map::local_index(k);
  const float l = admit(log_odds);
  b.log_odds[i] = l;
  const map::VoxelState before = b.state[i];
  const map::VoxelState after = classify(l);
  b.state[i] = after;
  grid_.note_transition(b, k, before, after);
}

void OccupancyMap::set_block_log_odds(const map::VoxelKey& block_key, const float* values) {
  map::VoxelBlock& b = grid_.get_or_create_block(block_key);
  for (int i = 0; i < map::kBlockVolume; ++i) {
    const map::VoxelState before = b.state[i];
    map::VoxelState after = map::VoxelState::kUnknown;
    float l = 0.0f;
    if (!std::isnan(values[i])) {
      l = admit(values[i]);
      after = classify(l);
    }
    b.log_odds[i] = l;
    b.state[i] = after;
    grid_.note_transition(b, map::voxel_of(block_key, i), before, after);
  }
}

}  // namespace semx::mapper
