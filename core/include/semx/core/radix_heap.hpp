// A min-priority queue of 64-bit keys for monotone use (no key pushed is below the last one
// popped), as in Dijkstra's search: a key goes to the bucket of the highest bit where it differs
// from the last key popped, and a bucket is split only when it is the lowest left (Ahuja, Mehlhorn,
// Orlin and Tarjan 1990). Pops come in the order of a binary heap's; each key is moved at most 64
// times, and in practice once or twice, where a binary heap of 10^6 entries moves each ~20 times.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace semx::core {

class RadixHeap {
 public:
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  uint64_t last() const { return last_; }

  // Throws when `key` is below the last key popped (the queue's order would be lost).
  void push(uint64_t key) {
    if (key < last_) throw std::logic_error("RadixHeap: a key below the last one popped");
    buckets_[bucket(key)].push_back(key);
    ++size_;
  }

  // The least key, removed. Undefined when empty.
  uint64_t pop() {
    if (buckets_[0].empty()) {
      size_t i = 1;
      while (buckets_[i].empty()) ++i;
      std::vector<uint64_t>& b = buckets_[i];
      last_ = *std::min_element(b.begin(), b.end());
      for (const uint64_t k : b) buckets_[bucket(k)].push_back(k);  // each to a lower bucket
      b.clear();
    }
    const uint64_t k = buckets_[0].back();
    buckets_[0].pop_back();
    --size_;
    return k;
  }

  // Empty, ready for keys from 0 again (the buckets keep their memory).
  void clear() {
    for (auto& b : buckets_) b.clear();
    size_ = 0;
    last_ = 0;
  }

 private:
  size_t bucket(uint64_t key) const {
    return key == last_ ? 0 : 64 - static_cast<size_t>(__builtin_clzll(key ^ last_));
  }

  std::array<std::vector<uint64_t>, 65> buckets_;
  size_t size_ = 0;
  uint64_t last_ = 0;
};

}  // namespace semx::core
