#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "semx/map/sort_keys.hpp"

using semx::map::VoxelKey;

namespace {

std::vector<VoxelKey> reference(std::vector<VoxelKey> keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

std::vector<VoxelKey> random_keys(int n, int32_t lo, int32_t hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int32_t> d(lo, hi);
  std::vector<VoxelKey> keys;
  for (int i = 0; i < n; ++i) keys.push_back({d(rng), d(rng), d(rng)});
  // Repeats, as the frontier bookkeeping's neighbour lists have.
  for (int i = 0; i < n / 2; ++i) keys.push_back(keys[static_cast<size_t>(i * 7 % n)]);
  return keys;
}

}  // namespace

TEST(SortKeys, GivesVoxelKeysOrderWithoutRepeatsAroundTheOrigin) {
  // Negative and positive coordinates, a narrow range so repeats abound.
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::vector<VoxelKey> keys = random_keys(seed % 2 ? 5000 : 300, -20, 20, seed);
    const std::vector<VoxelKey> want = reference(keys);
    semx::map::sort_unique(keys);
    EXPECT_EQ(keys, want) << "seed " << seed;
  }
}

TEST(SortKeys, KeysSpanningMoreThanThePackingStillSort) {
  // Keys at the limits of every axis need 87 bits: the packing cannot hold them, the comparison
  // takes over.
  const int32_t m = semx::map::kMaxKeyMagnitude - 1;
  std::vector<VoxelKey> keys = random_keys(2000, -100, 100, 7);
  keys.push_back({-m, 3, -m});
  keys.push_back({m, -m, 3});
  keys.push_back({0, m, m});
  const std::vector<VoxelKey> want = reference(keys);
  semx::map::sort_unique(keys);
  EXPECT_EQ(keys, want);
}

TEST(SortKeys, LongListsOfAWideMapSortAsShortOnes) {
  // 60 bits of packing (20 an axis): the radix sort's three passes, and the short lists' sort.
  for (int n : {100, 200000}) {
    std::vector<VoxelKey> keys = random_keys(n, -(1 << 19), (1 << 19) - 1, 11);
    keys.push_back({-(1 << 19), -(1 << 19), -(1 << 19)});
    keys.push_back({(1 << 19) - 1, (1 << 19) - 1, (1 << 19) - 1});
    const std::vector<VoxelKey> want = reference(keys);
    semx::map::sort_unique(keys);
    EXPECT_EQ(keys, want) << n << " keys";
  }
}

TEST(SortKeys, EmptyAndSingleKeysStay) {
  std::vector<VoxelKey> none;
  semx::map::sort_unique(none);
  EXPECT_TRUE(none.empty());
  std::vector<VoxelKey> one{{4, -5, 6}};
  semx::map::sort_unique(one);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0], (VoxelKey{4, -5, 6}));
}
