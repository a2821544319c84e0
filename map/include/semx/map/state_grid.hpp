// Sparse voxel-state storage (hashed 16^3 blocks) and the queries every map consumer needs.
//
// The mapper's OccupancyMap and every MapMirror keep their states in a StateGrid, so the
// queries below have one implementation and the mirror answers exactly what the mapper would.
// Definitions (DEP's, 6-connectivity):
//   frontier voxel: an unknown voxel with at least one free face neighbour;
//   surface voxel:  a frontier voxel with at least one occupied face neighbour.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "semx/map/raycast.hpp"
#include "semx/map/voxel_key.hpp"
#include "semx/map/voxel_state.hpp"

namespace semx::map {

struct VoxelBlock {
  VoxelKey key;                                  // block coordinates (voxel key >> kBlockBits)
  std::array<VoxelState, kBlockVolume> state{};  // value-initialised: all unknown
  std::unique_ptr<float[]> log_odds;             // OccupancyMap only; 0 for unknown voxels
  int32_t known = 0;                             // voxels of this block that are not unknown
};

class StateGrid {
 public:
  // with_log_odds: allocate a log-odds array with every block (the mapper's map); mirrors keep
  // states only.
  explicit StateGrid(double resolution, bool with_log_odds = false);
  StateGrid(StateGrid&&) = default;
  StateGrid& operator=(StateGrid&&) = default;

  double resolution() const { return km_.resolution(); }
  const KeyMath& keys() const { return km_; }
  bool with_log_odds() const { return with_log_odds_; }

  VoxelState state(const VoxelKey& k) const;
  // Unknown for points that are not finite or beyond the key range.
  VoxelState state(const Eigen::Vector3d& p) const;

  // Sets one voxel's state (allocating its block if needed) and keeps the counters true.
  // Setting kUnknown is allowed (snapshot/mirror replacement) and undoes the counts.
  void set_state(const VoxelKey& k, VoxelState s);

  // ---- block access for batch writers (integrator, decoders) ----
  const VoxelBlock* find_block(const VoxelKey& block_key) const;
  VoxelBlock* find_block(const VoxelKey& block_key);
  VoxelBlock& get_or_create_block(const VoxelKey& block_key);
  // Writers that change block->state[i] directly must report it here.
  void note_transition(VoxelBlock& b, const VoxelKey& k, VoxelState before, VoxelState after) {
    if (before == after) return;
    ++changes_;
    adjust(before, -1);
    adjust(after, +1);
    if (before == VoxelState::kUnknown) {
      ++b.known;
      known_bounds_.include(k);
    } else if (after == VoxelState::kUnknown) {
      --b.known;
    }
  }
  size_t num_blocks() const { return blocks_.size(); }
  // Grows with every state transition (and clear()): readers that cache what they derived from
  // the grid compare it to know whether their cache still holds.
  uint64_t changes() const { return changes_; }
  // Block keys in ascending (z, y, x) order, so every serialisation is deterministic.
  std::vector<VoxelKey> sorted_block_keys() const;
  template <class F>
  void for_each_block(F&& f) const {
    for (const auto& entry : blocks_) f(entry.second->key, *entry.second);
  }
  void clear();
  size_t memory_bytes() const;

  // ---- counters ----
  int64_t free_voxels() const { return free_; }
  int64_t occupied_voxels() const { return occupied_; }
  int64_t known_voxels() const { return free_ + occupied_; }
  // Bounding box of every voxel that has been known (grows only, except on clear()).
  const KeyBox& known_bounds() const { return known_bounds_; }

  // ---- queries ----
  bool is_frontier(const VoxelKey& k) const;
  bool is_surface(const VoxelKey& k) const;
  // Line of sight from `from` to `to`: true when no voxel on the segment, other than the one
  // containing `to`, is occupied (or unknown, when unknown_blocks). The start voxel counts, so a
  // viewpoint inside an obstacle sees nothing. Non-finite points are not visible.
  bool is_visible(const Eigen::Vector3d& from, const Eigen::Vector3d& to, bool unknown_blocks = false) const;
  // True when any voxel overlapping the open box (lo, hi) is occupied (or unknown, when
  // unknown_is_occupied). Voxels that only touch the box's faces do not count. Degenerate or
  // non-finite boxes collide (the safe answer).
  bool box_collides(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    bool unknown_is_occupied = true) const;
  // Number of frontier voxels in the whole map. Visits every allocated voxel: O(map), meant for
  // the 1 Hz MAP_STATS, not for every frame.
  int64_t count_frontiers() const;

  // True when both grids hold the same state for every voxel; optionally reports one voxel
  // where they differ.
  bool same_states(const StateGrid& other, VoxelKey* difference = nullptr) const;

  // A cursor caching the last block, for loops that look up many nearby voxels. Valid while the
  // grid does not gain or lose blocks.
  class Reader {
   public:
    explicit Reader(const StateGrid& g) : grid_(&g) {}
    VoxelState state(const VoxelKey& k) {
      const VoxelKey b = block_of(k);
      if (!valid_ || b != block_key_) {
        block_ = grid_->find_block(b);
        block_key_ = b;
        valid_ = true;
      }
      return block_ ? block_->state[local_index(k)] : VoxelState::kUnknown;
    }

   private:
    const StateGrid* grid_;
    const VoxelBlock* block_ = nullptr;
    VoxelKey block_key_;
    bool valid_ = false;
  };
  Reader reader() const { return Reader(*this); }

 private:
  void adjust(VoxelState s, int d) {
    if (s == VoxelState::kFree) free_ += d;
    if (s == VoxelState::kOccupied) occupied_ += d;
  }
  bool frontier_with(Reader& r, const VoxelKey& k) const;

  KeyMath km_;
  bool with_log_odds_;
  std::unordered_map<uint64_t, std::unique_ptr<VoxelBlock>, BlockHash> blocks_;
  int64_t free_ = 0;
  int64_t occupied_ = 0;
  uint64_t changes_ = 0;
  KeyBox known_bounds_;
};

}  // namespace semx::map
