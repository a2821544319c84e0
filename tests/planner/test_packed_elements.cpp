#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "semx/planner/packed_elements.hpp"

using semx::planner::MaskedElement;
using semx::planner::PackedElements;

namespace {

bool operator_less(const MaskedElement& a, const MaskedElement& b) { return a.element < b.element; }

std::vector<MaskedElement> unpacked(const PackedElements& p) {
  std::vector<MaskedElement> out;
  p.unpack(out);
  return out;
}

void expect_same(std::vector<MaskedElement> want, const std::vector<MaskedElement>& got) {
  std::sort(want.begin(), want.end(), operator_less);
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].element, want[i].element) << i;
    EXPECT_EQ(got[i].members, want[i].members) << "element " << want[i].element;
  }
}

}  // namespace

TEST(PackedElements, UnpacksWhatWasPackedInAscendingOrder) {
  // Every kind of mask: runs inside the word, runs through bit 31 into bit 0, one bit, all 32,
  // masks of several runs (kept raw), none; gaps of 0, of one varint byte, of several, the
  // largest element.
  std::vector<MaskedElement> v = {{5, 0x000000f0u},  {6, 0x80000003u},  {7, 0x1u},        {200, 0xffffffffu},
                                  {201, 0x0f0f0000u}, {202, 0x80000000u}, {203, 0u},        {70000, 0x7fffffffu},
                                  {70001, 0xfffffffeu}, {0x7fffffff, 0x00010001u}, {0, 0x00ff0000u}};
  std::shuffle(v.begin(), v.end(), std::mt19937(3));
  const PackedElements p(v);
  EXPECT_EQ(p.size(), v.size());
  expect_same(v, unpacked(p));
}

TEST(PackedElements, AViewOfYawRunsTakesAboutThreeBytesAVoxel) {
  // What a camera's 32 yaw bins give: each voxel seen from one run of 6-10 neighbouring bins,
  // the voxels close together in id (a surface's rows).
  std::mt19937 rng(11);
  std::vector<MaskedElement> v;
  int32_t id = 0;
  for (int i = 0; i < 50000; ++i) {
    id += 1 + static_cast<int32_t>(rng() % 4);
    const int start = static_cast<int>(rng() % 32), length = 6 + static_cast<int>(rng() % 5);
    const uint32_t run = (1u << length) - 1;
    v.push_back({id, (run << start) | (start ? run >> (32 - start) : 0)});
  }
  const PackedElements p(v);
  expect_same(v, unpacked(p));
  EXPECT_LE(p.bytes(), 3 * v.size());
  EXPECT_LT(p.bytes(), v.size() * sizeof(MaskedElement) / 2);
}

TEST(PackedElements, RefusesRepeatedAndNegativeElements) {
  EXPECT_THROW(PackedElements({{4, 1u}, {4, 2u}}), std::invalid_argument);
  EXPECT_THROW(PackedElements({{-1, 1u}}), std::invalid_argument);
  EXPECT_EQ(unpacked(PackedElements(std::vector<MaskedElement>{})).size(), 0u);
}
