// Integer voxel coordinates and the block tiling of the map.
//
// Voxel k covers [k*res, (k+1)*res) on each axis and its centre is (k + 0.5)*res, the same grid
// as OctoMap's (whose key is k + 32768), so the two maps can be compared voxel by voxel and the
// key goes on the wire unchanged (map_update_t).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>

namespace semx::map {

struct VoxelKey {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;

  constexpr VoxelKey() = default;
  constexpr VoxelKey(int32_t x_, int32_t y_, int32_t z_) : x(x_), y(y_), z(z_) {}

  int32_t operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  int32_t& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  friend constexpr bool operator==(const VoxelKey& a, const VoxelKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
  friend constexpr bool operator!=(const VoxelKey& a, const VoxelKey& b) { return !(a == b); }
  friend constexpr bool operator<(const VoxelKey& a, const VoxelKey& b) {
    return a.z != b.z ? a.z < b.z : (a.y != b.y ? a.y < b.y : a.x < b.x);
  }
  friend constexpr VoxelKey operator+(const VoxelKey& a, const VoxelKey& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
  }
  friend constexpr VoxelKey operator-(const VoxelKey& a, const VoxelKey& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
  }
};

// The six face neighbours, in the canonical order used wherever "the first neighbour" matters.
inline constexpr VoxelKey kFaceNeighbours[6] = {{-1, 0, 0}, {1, 0, 0},  {0, -1, 0},
                                                {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};

// Keys are kept far inside int32 so that neighbour and block arithmetic can never overflow; a
// pose or point beyond this is treated as invalid input, not silently wrapped.
inline constexpr int32_t kMaxKeyMagnitude = 1 << 28;

// Blocks of 16^3 voxels: large enough that the hash lookup is amortised over many voxels, small
// enough that a thin wall does not allocate much unknown space around it.
inline constexpr int kBlockBits = 4;
inline constexpr int kBlockSize = 1 << kBlockBits;
inline constexpr int kBlockMask = kBlockSize - 1;
inline constexpr int kBlockVolume = kBlockSize * kBlockSize * kBlockSize;

// Arithmetic shift is floor division for negative keys too (guaranteed since C++20 and by every
// compiler semx supports before that).
inline VoxelKey block_of(const VoxelKey& k) {
  return {k.x >> kBlockBits, k.y >> kBlockBits, k.z >> kBlockBits};
}
inline int local_index(const VoxelKey& k) {
  return (k.x & kBlockMask) | ((k.y & kBlockMask) << kBlockBits) | ((k.z & kBlockMask) << (2 * kBlockBits));
}
// (Multiplications, not shifts: left-shifting a negative key is undefined before C++20.)
inline VoxelKey voxel_of(const VoxelKey& block, int local) {
  return {block.x * kBlockSize + (local & kBlockMask),
          block.y * kBlockSize + ((local >> kBlockBits) & kBlockMask),
          block.z * kBlockSize + (local >> (2 * kBlockBits))};
}

// One 64-bit word per block key for hashing; 21 bits per axis holds every block within
// kMaxKeyMagnitude.
inline uint64_t pack_block(const VoxelKey& b) {
  constexpr uint64_t m = (uint64_t{1} << 21) - 1;
  return (static_cast<uint64_t>(static_cast<uint32_t>(b.x)) & m) |
         ((static_cast<uint64_t>(static_cast<uint32_t>(b.y)) & m) << 21) |
         ((static_cast<uint64_t>(static_cast<uint32_t>(b.z)) & m) << 42);
}

struct BlockHash {
  size_t operator()(uint64_t packed) const {
    // splitmix64 finaliser: packed keys differ in few low bits, std::hash<uint64_t> is identity.
    packed ^= packed >> 30;
    packed *= 0xbf58476d1ce4e5b9ULL;
    packed ^= packed >> 27;
    packed *= 0x94d049bb133111ebULL;
    packed ^= packed >> 31;
    return static_cast<size_t>(packed);
  }
};

struct VoxelKeyHash {
  size_t operator()(const VoxelKey& k) const {
    return BlockHash()(static_cast<uint64_t>(static_cast<uint32_t>(k.x)) ^
                       (static_cast<uint64_t>(static_cast<uint32_t>(k.y)) << 21) ^
                       (static_cast<uint64_t>(static_cast<uint32_t>(k.z)) << 42));
  }
};

// Inclusive box of keys; empty when min > max on any axis.
struct KeyBox {
  VoxelKey min{1, 1, 1};
  VoxelKey max{0, 0, 0};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void include(const VoxelKey& k) {
    if (empty()) {
      min = max = k;
      return;
    }
    min = {std::min(min.x, k.x), std::min(min.y, k.y), std::min(min.z, k.z)};
    max = {std::max(max.x, k.x), std::max(max.y, k.y), std::max(max.z, k.z)};
  }
  void include(const KeyBox& b) {
    if (b.empty()) return;
    include(b.min);
    include(b.max);
  }
  bool contains(const VoxelKey& k) const {
    return k.x >= min.x && k.x <= max.x && k.y >= min.y && k.y <= max.y && k.z >= min.z && k.z <= max.z;
  }
  bool intersects(const KeyBox& b) const {
    return !empty() && !b.empty() && min.x <= b.max.x && b.min.x <= max.x && min.y <= b.max.y &&
           b.min.y <= max.y && min.z <= b.max.z && b.min.z <= max.z;
  }
};

// Point <-> key with a given resolution. Multiplying by the inverse resolution (rather than
// dividing) matches OctoMap's coordToKey, so boundary points fall in the same voxel in both.
class KeyMath {
 public:
  explicit KeyMath(double resolution) : res_(resolution), inv_res_(1.0 / resolution) {}

  double resolution() const { return res_; }
  double inv_resolution() const { return inv_res_; }

  // False when p is not finite or beyond kMaxKeyMagnitude voxels from the origin.
  bool key(const Eigen::Vector3d& p, VoxelKey& out) const {
    for (int i = 0; i < 3; ++i) {
      const double s = std::floor(p[i] * inv_res_);
      if (!(std::abs(s) < kMaxKeyMagnitude)) return false;  // also rejects NaN
      out[i] = static_cast<int32_t>(s);
    }
    return true;
  }
  // For points already known to be valid.
  VoxelKey key(const Eigen::Vector3d& p) const {
    return {static_cast<int32_t>(std::floor(p.x() * inv_res_)),
            static_cast<int32_t>(std::floor(p.y() * inv_res_)),
            static_cast<int32_t>(std::floor(p.z() * inv_res_))};
  }
  Eigen::Vector3d center(const VoxelKey& k) const {
    return {(k.x + 0.5) * res_, (k.y + 0.5) * res_, (k.z + 0.5) * res_};
  }
  // Minimum corner of voxel k.
  Eigen::Vector3d corner(const VoxelKey& k) const { return {k.x * res_, k.y * res_, k.z * res_}; }

 private:
  double res_;
  double inv_res_;
};

}  // namespace semx::map

namespace std {
template <>
struct hash<semx::map::VoxelKey> : semx::map::VoxelKeyHash {};
}  // namespace std
