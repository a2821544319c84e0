#include "semx/map/sort_keys.hpp"

#include <algorithm>
#include <cstdint>

#include "semx/core/radix_sort.hpp"

namespace semx::map {

void sort_unique(std::vector<VoxelKey>& keys) {
  if (keys.size() < 2) return;
  VoxelKey lo = keys.front(), hi = keys.front();
  for (const VoxelKey& k : keys)
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], k[i]);
      hi[i] = std::max(hi[i], k[i]);
    }
  // Each axis gets the bits its span needs, z highest: the integers' order is VoxelKey's.
  int bits[3];
  int total = 0;
  for (int i = 0; i < 3; ++i) {
    const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi[i]) - lo[i]);
    bits[i] = 0;
    while (bits[i] < 64 && (span >> bits[i]) != 0) ++bits[i];
    total += bits[i];
  }
  if (total > 63) {
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    return;
  }
  std::vector<uint64_t> packed(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    const VoxelKey& k = keys[i];
    packed[i] = (static_cast<uint64_t>(k.z - lo.z) << (bits[0] + bits[1])) |
                (static_cast<uint64_t>(k.y - lo.y) << bits[0]) | static_cast<uint64_t>(k.x - lo.x);
  }
  // A map's keys need 2 or 3 radix passes, each linear (std::sort on the packings was still 6 %
  // of FUEL's cycle).
  core::radix_sort(packed, 0, total);
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  keys.resize(packed.size());
  const uint64_t mx = (uint64_t{1} << bits[0]) - 1, my = (uint64_t{1} << bits[1]) - 1;
  for (size_t i = 0; i < packed.size(); ++i) {
    const uint64_t p = packed[i];
    keys[i] = {lo.x + static_cast<int32_t>(p & mx), lo.y + static_cast<int32_t>((p >> bits[0]) & my),
               lo.z + static_cast<int32_t>(p >> (bits[0] + bits[1]))};
  }
}

}  // namespace semx::map
