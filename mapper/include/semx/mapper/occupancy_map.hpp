// The mapper's log-odds occupancy map: a map::StateGrid whose blocks also carry log-odds.
//
// Update rule (OctoMap's): l <- clamp(l + l_hit) for a voxel an observation ends in, l <- clamp(l +
// l_miss) for a voxel a ray passes through, with l starting at 0 for a never-observed voxel, in
// float arithmetic with the constants computed as OctoMap computes them, so the same sequence of
// per-voxel observations gives bit-identical log-odds in both. A voxel is occupied iff l >=
// logit(threshold), free otherwise, unknown until first observed.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <optional>

#include "semx/map/state_grid.hpp"
#include "semx/mapper/mapper_config.hpp"

namespace semx::mapper {

class OccupancyMap {
 public:
  // Throws runtime::ConfigError for inconsistent parameters.
  explicit OccupancyMap(const OccupancyParams& params);
  OccupancyMap(OccupancyMap&&) = default;
  OccupancyMap& operator=(OccupancyMap&&) = default;

  const OccupancyParams& params() const { return params_; }
  double resolution() const { return grid_.resolution(); }
  const map::KeyMath& keys() const { return grid_.keys(); }
  const map::StateGrid& grid() const { return grid_; }

  float hit_log_odds() const { return l_hit_; }
  float miss_log_odds() const { return l_miss_; }
  float min_log_odds() const { return l_min_; }
  float max_log_odds() const { return l_max_; }
  float threshold_log_odds() const { return l_occ_; }
  // The log-odds of a held voxel (OccupancyParams::hold_range): above every clamped value, so a
  // checkpoint keeps it and classify() calls it occupied.
  static constexpr float kHeld = std::numeric_limits<float>::infinity();
  bool is_held(const map::VoxelKey& k) const;
  map::VoxelState classify(float log_odds) const {
    return log_odds >= l_occ_ ? map::VoxelState::kOccupied : map::VoxelState::kFree;
  }

  // Whether updates may touch voxel k (always true without configured bounds).
  bool in_bounds(const map::VoxelKey& k) const { return !bounded_ || bounds_.contains(k); }
  // The updatable key box; empty optional when unbounded.
  std::optional<map::KeyBox> bounds() const {
    return bounded_ ? std::optional<map::KeyBox>(bounds_) : std::nullopt;
  }

  map::VoxelState state(const map::VoxelKey& k) const { return grid_.state(k); }
  map::VoxelState state(const Eigen::Vector3d& p) const { return grid_.state(p); }
  // Log-odds of a known voxel; nullopt for unknown ones.
  std::optional<float> log_odds(const map::VoxelKey& k) const;

  // One observation of one voxel (integration applies at most one per voxel per frame). Returns
  // the new state; *changed tells whether the state changed. Out-of-bounds voxels are ignored.
  // `near`: the hit came from within hold_range (ignored for misses and when hold_range is 0).
  map::VoxelState update(const map::VoxelKey& k, bool hit, bool* changed = nullptr, bool near = false);
  // Sets a voxel's log-odds (clamped into [min, max], kHeld kept); NaN makes the voxel unknown again.
  // For restoring checkpoints and building test scenes.
  void set_log_odds(const map::VoxelKey& k, float log_odds);
  // The same for a whole block: values[i] for local index i (NaN = unknown).
  void set_block_log_odds(const map::VoxelKey& block_key, const float* values);
  void clear() { grid_.clear(); }

  // Batch path for the integrator: applies one observation to voxel i of block b and returns
  // the state before and after.
  void apply(map::VoxelBlock& b, const map::VoxelKey& k, int i, bool hit, bool near, map::VoxelState& before,
             map::VoxelState& after) {
    before = b.state[i];
    // kHeld + l_miss stays kHeld, so a held voxel needs no test of its own.
    float l = b.log_odds[i] + (hit ? l_hit_ : l_miss_);
    if (l < l_min_) l = l_min_;
    if (l >= l_max_ && l != kHeld) l = hit && near && hold_ ? kHeld : l_max_;
    b.log_odds[i] = l;
    after = classify(l);
    if (after != before) {
      b.state[i] = after;
      grid_.note_transition(b, k, before, after);
    }
  }
  map::VoxelBlock& block(const map::VoxelKey& block_key) { return grid_.get_or_create_block(block_key); }

  // ---- the shared queries (see map::StateGrid) ----
  bool is_frontier(const map::VoxelKey& k) const { return grid_.is_frontier(k); }
  bool is_surface(const map::VoxelKey& k) const { return grid_.is_surface(k); }
  bool is_visible(const Eigen::Vector3d& from, const Eigen::Vector3d& to, bool unknown_blocks = false) const {
    return grid_.is_visible(from, to, unknown_blocks);
  }
  bool box_collides(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    bool unknown_is_occupied = true) const {
    return grid_.box_collides(lo, hi, unknown_is_occupied);
  }
  int64_t count_frontiers() const { return grid_.count_frontiers(); }

 private:
  // A stored or restored value: kHeld stays held while holding is on (only apply() makes it, so a
  // checkpoint keeps it), anything else is clamped.
  float admit(float l) const { return l == kHeld && hold_ ? l : std::min(std::max(l, l_min_), l_max_); }
  OccupancyParams params_;
  map::StateGrid grid_;
  float l_hit_, l_miss_, l_min_, l_max_, l_occ_;
  bool hold_;  // hold_range > 0
  bool bounded_ = false;
  map::KeyBox bounds_;
};

}  // namespace semx::mapper
