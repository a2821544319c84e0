#include "semx/map/sort_keys.hpp"

#include <algorithm>
#include <cstdint>

namespace semx::map {

void sort_unique(std::vector<VoxelKey>& keys) {
  if (keys.size() < 2) return;
  VoxelKey lo = keys.front(), hi = keys.front();
  for (const VoxelKey& k : keys)
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], k[i]);
      hi[i] = std::max(hi[i], k[i]);
    }
  constexpr int kBits = 21;
  constexpr int64_t kSpan = int64_t{1} << kBits;
  for (int i = 0; i < 3; ++i) {
    if (static_cast<int64_t>(hi[i]) - lo[i] >= kSpan) {
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
      return;
    }
  }
  // z in the high bits, x in the low ones: the integers' order is VoxelKey's.
  std::vector<uint64_t> packed(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    const VoxelKey& k = keys[i];
    packed[i] = (static_cast<uint64_t>(k.z - lo.z) << (2 * kBits)) |
                (static_cast<uint64_t>(k.y - lo.y) << kBits) | static_cast<uint64_t>(k.x - lo.x);
  }
  std::sort(packed.begin(), packed.end());
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  constexpr uint64_t kMask = static_cast<uint64_t>(kSpan - 1);
  keys.resize(packed.size());
  for (size_t i = 0; i < packed.size(); ++i) {
    const uint64_t p = packed[i];
    keys[i] = {lo.x + static_cast<int32_t>(p & kMask), lo.y + static_cast<int32_t>((p >> kBits) & kMask),
               lo.z + static_cast<int32_t>(p >> (2 * kBits))};
  }
}

}  // namespace semx::map
