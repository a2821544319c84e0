#include "semx/map/state_grid.hpp"

#include <algorithm>
#include <cmath>

namespace semx::map {

StateGrid::StateGrid(double resolution, bool with_log_odds)
    : km_(resolution), with_log_odds_(with_log_odds) {}

const VoxelBlock* StateGrid::find_block(const VoxelKey& block_key) const {
  auto it = blocks_.find(pack_block(block_key));
  return it == blocks_.end() ? nullptr : it->second.get();
}

VoxelBlock* StateGrid::find_block(const VoxelKey& block_key) {
  auto it = blocks_.find(pack_block(block_key));
  return it == blocks_.end() ? nullptr : it->second.get();
}

VoxelBlock& StateGrid::get_or_create_block(const VoxelKey& block_key) {
  auto& slot = blocks_[pack_block(block_key)];
  if (!slot) {
    slot = std::make_unique<VoxelBlock>();
    slot->key = block_key;
    if (with_log_odds_) slot->log_odds.reset(new float[kBlockVolume]());
  }
  return *slot;
}

VoxelState StateGrid::state(const VoxelKey& k) const {
  const VoxelBlock* b = find_block(block_of(k));
  return b ? b->state[local_index(k)] : VoxelState::kUnknown;
}

VoxelState StateGrid::state(const Eigen::Vector3d& p) const {
  VoxelKey k;
  if (!km_.key(p, k)) return VoxelState::kUnknown;
  return state(k);
}

void StateGrid::set_state(const VoxelKey& k, VoxelState s) {
  VoxelBlock* b = find_block(block_of(k));
  if (!b) {
    if (s == VoxelState::kUnknown) return;
    b = &get_or_create_block(block_of(k));
  }
  const int i = local_index(k);
  const VoxelState before = b->state[i];
  b->state[i] = s;
  if (s == VoxelState::kUnknown && b->log_odds) b->log_odds[i] = 0.0f;
  note_transition(*b, k, before, s);
}

std::vector<VoxelKey> StateGrid::sorted_block_keys() const {
  std::vector<VoxelKey> keys;
  keys.reserve(blocks_.size());
  for (const auto& entry : blocks_) keys.push_back(entry.second->key);
  std::sort(keys.begin(), keys.end());
  return keys;
}

void StateGrid::clear() {
  blocks_.clear();
  free_ = occupied_ = 0;
  ++changes_;
  known_bounds_ = KeyBox();
}

size_t StateGrid::memory_bytes() const {
  const size_t per_block = sizeof(VoxelBlock) + (with_log_odds_ ? kBlockVolume * sizeof(float) : 0);
  // Hash node and bucket overhead, roughly; the figure is for MAP_STATS, not accounting.
  return blocks_.size() * (per_block + 48);
}

bool StateGrid::frontier_with(Reader& r, const VoxelKey& k) const {
  if (r.state(k) != VoxelState::kUnknown) return false;
  for (const VoxelKey& d : kFaceNeighbours) {
    if (r.state(k + d) == VoxelState::kFree) return true;
  }
  return false;
}

bool StateGrid::is_frontier(const VoxelKey& k) const {
  Reader r(*this);
  return frontier_with(r, k);
}

bool StateGrid::is_surface(const VoxelKey& k) const {
  Reader r(*this);
  if (!frontier_with(r, k)) return false;
  for (const VoxelKey& d : kFaceNeighbours) {
    if (r.state(k + d) == VoxelState::kOccupied) return true;
  }
  return false;
}

bool StateGrid::is_visible(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                           bool unknown_blocks) const {
  VoxelKey end;
  if (!km_.key(to, end)) return false;
  Reader r(*this);
  return traverse_segment(km_, from, to, [&](const VoxelKey& k) {
    if (k == end) return true;
    const VoxelState s = r.state(k);
    return !(s == VoxelState::kOccupied || (unknown_blocks && s == VoxelState::kUnknown));
  });
}

bool StateGrid::box_collides(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                             bool unknown_is_occupied) const {
  VoxelKey kmin, kmax;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i]) || !(lo[i] < hi[i])) return true;
    const double a = std::floor(lo[i] * km_.inv_resolution());
    const double b = std::ceil(hi[i] * km_.inv_resolution()) - 1.0;
    if (std::abs(a) >= kMaxKeyMagnitude || std::abs(b) >= kMaxKeyMagnitude) return true;
    kmin[i] = static_cast<int32_t>(a);
    kmax[i] = static_cast<int32_t>(b);
  }
  // Block by block, so a large box costs one hash lookup per block rather than per voxel.
  const VoxelKey bmin = block_of(kmin), bmax = block_of(kmax);
  for (int32_t bz = bmin.z; bz <= bmax.z; ++bz) {
    for (int32_t by = bmin.y; by <= bmax.y; ++by) {
      for (int32_t bx = bmin.x; bx <= bmax.x; ++bx) {
        const VoxelBlock* b = find_block({bx, by, bz});
        if (!b) {
          if (unknown_is_occupied) return true;
          continue;
        }
        const VoxelKey base{bx * kBlockSize, by * kBlockSize, bz * kBlockSize};
        const int x0 = std::max(kmin.x, base.x) - base.x, x1 = std::min(kmax.x, base.x + kBlockMask) - base.x;
        const int y0 = std::max(kmin.y, base.y) - base.y, y1 = std::min(kmax.y, base.y + kBlockMask) - base.y;
        const int z0 = std::max(kmin.z, base.z) - base.z, z1 = std::min(kmax.z, base.z + kBlockMask) - base.z;
        for (int z = z0; z <= z1; ++z) {
          for (int y = y0; y <= y1; ++y) {
            const VoxelState* row = &b->state[(z << (2 * kBlockBits)) | (y << kBlockBits)];
            for (int x = x0; x <= x1; ++x) {
              const VoxelState s = row[x];
              if (s == VoxelState::kOccupied || (unknown_is_occupied && s == VoxelState::kUnknown))
                return true;
            }
          }
        }
      }
    }
  }
  return false;
}

int64_t StateGrid::count_frontiers() const {
  // Unknown voxels inside allocated blocks are tested directly. Unknown voxels in unallocated
  // blocks can only be frontiers through a free neighbour in an allocated block; each is counted
  // once, by its first free neighbour in kFaceNeighbours order.
  int64_t count = 0;
  Reader r(*this);
  Reader probe(*this);
  for (const auto& entry : blocks_) {
    const VoxelBlock& b = *entry.second;
    const VoxelKey base{b.key.x * kBlockSize, b.key.y * kBlockSize, b.key.z * kBlockSize};
    for (int i = 0; i < kBlockVolume; ++i) {
      const VoxelState s = b.state[i];
      const int x = i & kBlockMask, y = (i >> kBlockBits) & kBlockMask, z = i >> (2 * kBlockBits);
      const bool interior = x > 0 && x < kBlockMask && y > 0 && y < kBlockMask && z > 0 && z < kBlockMask;
      if (s == VoxelState::kUnknown) {
        if (interior) {
          if (b.state[i - 1] == VoxelState::kFree || b.state[i + 1] == VoxelState::kFree ||
              b.state[i - kBlockSize] == VoxelState::kFree || b.state[i + kBlockSize] == VoxelState::kFree ||
              b.state[i - kBlockSize * kBlockSize] == VoxelState::kFree ||
              b.state[i + kBlockSize * kBlockSize] == VoxelState::kFree) {
            ++count;
          }
        } else {
          const VoxelKey k{base.x + x, base.y + y, base.z + z};
          for (const VoxelKey& d : kFaceNeighbours) {
            if (r.state(k + d) == VoxelState::kFree) {
              ++count;
              break;
            }
          }
        }
      } else if (s == VoxelState::kFree && !interior) {
        const VoxelKey k{base.x + x, base.y + y, base.z + z};
        for (const VoxelKey& d : kFaceNeighbours) {
          const VoxelKey n = k + d;
          if (block_of(n) == b.key || find_block(block_of(n))) continue;
          for (const VoxelKey& e : kFaceNeighbours) {
            if (probe.state(n + e) == VoxelState::kFree) {
              if (n + e == k) ++count;
              break;
            }
          }
        }
      }
    }
  }
  return count;
}

bool StateGrid::same_states(const StateGrid& other, VoxelKey* difference) const {
  auto compare = [&](const StateGrid& a, const StateGrid& b) {
    for (const auto& entry : a.blocks_) {
      const VoxelBlock& ba = *entry.second;
      const VoxelBlock* bb = b.find_block(ba.key);
      for (int i = 0; i < kBlockVolume; ++i) {
        const VoxelState sb = bb ? bb->state[i] : VoxelState::kUnknown;
        if (ba.state[i] != sb) {
          if (difference) *difference = voxel_of(ba.key, i);
          return false;
        }
      }
    }
    return true;
  };
  if (free_ != other.free_ || occupied_ != other.occupied_) {
    // Counts differ: still locate a differing voxel for the caller's message.
    if (!compare(*this, other)) return false;
    compare(other, *this);
    return false;
  }
  return compare(*this, other) && compare(other, *this);
}

}  // namespace semx::map
