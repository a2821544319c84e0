#include <gtest/gtest.h>

#include <functional>
#include <queue>
#include <random>
#include <stdexcept>
#include <vector>

#include "semx/core/radix_heap.hpp"

using semx::core::RadixHeap;

TEST(RadixHeap, PopsWhatABinaryHeapPopsUnderMonotoneUse) {
  // Dijkstra's pattern: pop the least, push a few keys at or above it (repeats included), with
  // keys spread over many bit lengths.
  std::mt19937_64 rng(5);
  RadixHeap radix;
  std::priority_queue<uint64_t, std::vector<uint64_t>, std::greater<uint64_t>> binary;
  for (uint64_t k : {uint64_t{0}, uint64_t{7}, uint64_t{7}, uint64_t{1} << 40}) radix.push(k), binary.push(k);
  int popped = 0;
  while (!binary.empty() && popped < 200000) {
    ASSERT_EQ(radix.size(), binary.size());
    const uint64_t want = binary.top();
    binary.pop();
    ASSERT_EQ(radix.pop(), want) << "pop " << popped;
    ++popped;
    if (popped < 20000) {
      const int n = static_cast<int>(rng() % 4);
      for (int j = 0; j < n; ++j) {
        const uint64_t k = want + (rng() >> (20 + rng() % 44));
        radix.push(k);
        binary.push(k);
      }
    }
  }
  EXPECT_TRUE(radix.empty());
  EXPECT_GT(popped, 20000);
}

TEST(RadixHeap, RefusesAKeyBelowTheLastPopped) {
  RadixHeap h;
  h.push(10);
  h.push(20);
  EXPECT_EQ(h.pop(), 10u);
  EXPECT_THROW(h.push(9), std::logic_error);
  h.push(10);
  EXPECT_EQ(h.pop(), 10u);
  h.clear();
  EXPECT_TRUE(h.empty());
  h.push(1);
  EXPECT_EQ(h.pop(), 1u);
}
