#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "semx/core/radix_sort.hpp"

using semx::core::radix_sort;

namespace {

// std::stable_sort by the same band of bits: what radix_sort must give, order of ties included.
std::vector<uint64_t> reference(std::vector<uint64_t> v, int from, int to) {
  const uint64_t band = to - from == 64 ? ~uint64_t{0} : ((uint64_t{1} << (to - from)) - 1);
  std::stable_sort(v.begin(), v.end(),
                   [&](uint64_t a, uint64_t b) { return ((a >> from) & band) < ((b >> from) & band); });
  return v;
}

std::vector<uint64_t> random_values(size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> v(n);
  for (auto& x : v) x = rng();
  return v;
}

}  // namespace

TEST(RadixSort, GivesAStableSortByTheBand) {
  // Long lists take the radix passes, short ones the comparison sort; bands of one digit, of a
  // digit and a bit (the last pass must not read past the band), of the whole word.
  for (size_t n : {size_t{0}, size_t{1}, size_t{100}, size_t{5000}, size_t{40000}})
    for (auto [from, to] : {std::pair{0, 64}, std::pair{32, 63}, std::pair{3, 15}, std::pair{20, 31}, std::pair{5, 5}}) {
      std::vector<uint64_t> v = random_values(n, static_cast<unsigned>(n + 7 * from + to));
      const std::vector<uint64_t> want = reference(v, from, to);
      radix_sort(v, from, to);
      EXPECT_EQ(v, want) << n << " values, bits " << from << "-" << to;
    }
}

TEST(RadixSort, RejectsABandOutsideTheWord) {
  std::vector<uint64_t> v{3, 1, 2};
  EXPECT_THROW(radix_sort(v, -1, 10), std::invalid_argument);
  EXPECT_THROW(radix_sort(v, 0, 65), std::invalid_argument);
  EXPECT_THROW(radix_sort(v, 10, 9), std::invalid_argument);
}
