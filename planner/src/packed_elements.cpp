#include "semx/planner/packed_elements.hpp"

#include <stdexcept>

#include "semx/core/radix_sort.hpp"

namespace semx::planner {

namespace {

// A run's start byte is below 32; this one says four raw mask bytes follow.
constexpr uint8_t kRawMask = 0xff;

// Start and length (1-32) of the mask's one circular run of set bits, or false.
bool one_run(uint32_t m, int& start, int& length) {
  if (m == 0) return false;
  if (m == ~uint32_t{0}) {
    start = 0;
    length = 32;
    return true;
  }
  // The run starts at a set bit whose lower neighbour (circularly) is clear; one run has one.
  const uint32_t starts = m & ~((m << 1) | (m >> 31));
  if (starts & (starts - 1)) return false;
  start = __builtin_ctz(starts);
  const uint32_t rotated = (m >> start) | (start ? m << (32 - start) : 0);
  length = __builtin_ctz(~rotated);
  return true;
}

}  // namespace

PackedElements::PackedElements(const std::vector<MaskedElement>& elements) : count_(elements.size()) {
  // Sorted by element through 64-bit packings (element above, mask below).
  std::vector<uint64_t> keys(elements.size());
  for (size_t i = 0; i < elements.size(); ++i) {
    if (elements[i].element < 0) throw std::invalid_argument("PackedElements: negative element");
    keys[i] = static_cast<uint64_t>(elements[i].element) << 32 | elements[i].members;
  }
  core::radix_sort(keys, 32, 63);
  // One encoder, run twice: counting the bytes, then writing them into a buffer of that exact
  // size (a kept view's memory is its capacity, and thousands are kept).
  auto encode = [&](auto&& put) {
    int64_t previous = -1;
    for (const uint64_t k : keys) {
      const int64_t e = static_cast<int64_t>(k >> 32);
      if (e == previous) throw std::invalid_argument("PackedElements: repeated element");
      for (uint64_t gap = static_cast<uint64_t>(e - previous - 1);; gap >>= 7) {
        put(static_cast<uint8_t>((gap & 0x7f) | (gap >= 0x80 ? 0x80 : 0)));
        if (gap < 0x80) break;
      }
      previous = e;
      const uint32_t m = static_cast<uint32_t>(k);
      int start = 0, length = 0;
      if (one_run(m, start, length)) {
        put(static_cast<uint8_t>(start));
        put(static_cast<uint8_t>(length));
      } else {
        put(kRawMask);
        for (int b = 0; b < 4; ++b) put(static_cast<uint8_t>(m >> (8 * b)));
      }
    }
  };
  size_t bytes = 0;
  encode([&](uint8_t) { ++bytes; });
  data_.reserve(bytes);
  encode([&](uint8_t b) { data_.push_back(b); });
}

void PackedElements::unpack(std::vector<MaskedElement>& out) const {
  out.resize(count_);
  const uint8_t* p = data_.data();
  int64_t previous = -1;
  for (size_t i = 0; i < count_; ++i) {
    uint64_t gap = 0;
    for (int shift = 0;; shift += 7) {
      const uint8_t b = *p++;
      gap |= static_cast<uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) break;
    }
    previous += static_cast<int64_t>(gap) + 1;
    uint32_t m = 0;
    if (*p == kRawMask) {
      ++p;
      for (int b = 0; b < 4; ++b) m |= static_cast<uint32_t>(*p++) << (8 * b);
    } else {
      const int start = p[0], length = p[1];
      p += 2;
      const uint32_t run = length == 32 ? ~uint32_t{0} : (uint32_t{1} << length) - 1;
      m = (run << start) | (start ? run >> (32 - start) : 0);
    }
    out[i] = {static_cast<int32_t>(previous), m};
  }
}

}  // namespace semx::planner
