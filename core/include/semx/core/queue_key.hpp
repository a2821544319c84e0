// A search's queue entry (cost, index) as one 64-bit key: the bits of a float >= 0 order as the
// float does, so one integer comparison orders entries as the pair (cost, index) does, ties to the
// lower index. A binary heap sifts with one compare instead of the pair's two, and a RadixHeap
// (radix_heap.hpp) takes the keys as they are. Costs must be >= +0 (not -0, not NaN).
#pragma once

#include <cstdint>
#include <cstring>

namespace semx::core {

inline uint64_t queue_key(float cost, uint32_t index) {
  uint32_t bits = 0;
  std::memcpy(&bits, &cost, sizeof bits);
  return static_cast<uint64_t>(bits) << 32 | index;
}

inline uint32_t queue_key_index(uint64_t key) { return static_cast<uint32_t>(key); }

inline float queue_key_cost(uint64_t key) {
  const uint32_t bits = static_cast<uint32_t>(key >> 32);
  float cost = 0.0f;
  std::memcpy(&cost, &bits, sizeof cost);
  return cost;
}

}  // namespace semx::core
