// VoxelSet against std::unordered_set on random keys around block boundaries and the origin.
#include <gtest/gtest.h>

#include <random>
#include <unordered_set>

#include "semx/planner/voxel_set.hpp"

namespace semx::planner {
namespace {

using map::VoxelKey;

TEST(VoxelSet, AgreesWithAHashSet) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> u(-40, 40);
  VoxelSet s;
  std::unordered_set<VoxelKey> ref;
  for (int i = 0; i < 20000; ++i) {
    const VoxelKey k{u(rng), u(rng), u(rng) / 4};
    EXPECT_EQ(s.insert(k), ref.insert(k).second);
  }
  EXPECT_EQ(s.size(), ref.size());
  for (int i = 0; i < 20000; ++i) {
    const VoxelKey k{u(rng), u(rng), u(rng) / 4};
    ASSERT_EQ(s.contains(k), ref.count(k) == 1) << k.x << " " << k.y << " " << k.z;
  }
  s.clear();
  EXPECT_TRUE(s.empty());
  EXPECT_FALSE(s.contains(*ref.begin()));
}

TEST(VoxelSet, BlockMasksHoldTheirBlocksMembersOnly) {
  VoxelSet s;
  s.insert({-1, 0, 0});               // block (-1, 0, 0)
  s.insert({map::kBlockSize, 0, 0});  // block (1, 0, 0)
  EXPECT_EQ(s.block_mask({0, 0, 0}), nullptr);
  const VoxelSet::Mask* m = s.block_mask({-1, 0, 0});
  ASSERT_NE(m, nullptr);
  EXPECT_TRUE(VoxelSet::test(*m, map::local_index({-1, 0, 0})));
  EXPECT_FALSE(VoxelSet::test(*m, map::local_index({-2, 0, 0})));
  ASSERT_NE(s.block_mask({1, 0, 0}), nullptr);
  EXPECT_TRUE(VoxelSet::test(*s.block_mask({1, 0, 0}), 0));
  EXPECT_FALSE(s.insert({-1, 0, 0}));
  EXPECT_EQ(s.size(), 2u);
}

}  // namespace
}  // namespace semx::planner
