#include "semx/core/radix_sort.hpp"

#include <algorithm>
#include <stdexcept>

namespace semx::core {

void radix_sort(std::vector<uint64_t>& values, int from_bit, int to_bit) {
  if (from_bit < 0 || to_bit > 64 || from_bit > to_bit) throw std::invalid_argument("radix_sort: bits out of range");
  if (from_bit == to_bit || values.size() < 2) return;
  const uint64_t band = to_bit - from_bit == 64 ? ~uint64_t{0} : ((uint64_t{1} << (to_bit - from_bit)) - 1);
  // Short lists do not pay for the buckets.
  if (values.size() < 1024) {
    std::stable_sort(values.begin(), values.end(), [&](uint64_t a, uint64_t b) {
      return ((a >> from_bit) & band) < ((b >> from_bit) & band);
    });
    return;
  }
  constexpr int kDigit = 11;
  constexpr size_t kBuckets = size_t{1} << kDigit;
  std::vector<size_t> count(kBuckets);
  std::vector<uint64_t> other(values.size());
  for (int shift = from_bit; shift < to_bit; shift += kDigit) {
    // The last digit may reach past to_bit: its bits above the band must not count.
    const uint64_t digit = std::min(kBuckets - 1, static_cast<size_t>(band >> (shift - from_bit)));
    std::fill(count.begin(), count.end(), 0);
    for (uint64_t v : values) ++count[(v >> shift) & digit];
    size_t sum = 0;
    for (size_t& c : count) {
      const size_t n = c;
      c = sum;
      sum += n;
    }
    for (uint64_t v : values) other[count[(v >> shift) & digit]++] = v;
    values.swap(other);
  }
}

}  // namespace semx::core
