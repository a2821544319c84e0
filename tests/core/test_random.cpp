// The draws are defined bit for bit: the engines against their authors' reference outputs, the
// draws against their definitions, so a seed means the same run on every platform.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "semx/core/random.hpp"

namespace semx::core {
namespace {

TEST(Random, SplitMix64IsTheReferenceGenerator) {
  // splitmix64.c (Vigna) from state 0: its first outputs.
  uint64_t state = 0;
  auto reference = [&state] { return splitmix64_mix(state += kGoldenGamma); };
  EXPECT_EQ(reference(), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(reference(), 0x6E789E6AA1B965F4ull);
  // The engine seeded with s discards one draw: its first output is the reference's second from s.
  SplitMix64 e(0);
  EXPECT_EQ(e.next(), 0x6E789E6AA1B965F4ull);
  EXPECT_EQ(e.next(), 0x06C45D188009454Full);
}

TEST(Random, Xoshiro256StarStarIsTheReferenceGenerator) {
  // xoshiro256starstar.c (Blackman & Vigna) from the state {1, 2, 3, 4}: its first outputs.
  Xoshiro256StarStar e(std::array<uint64_t, 4>{1, 2, 3, 4});
  EXPECT_EQ(e.next(), 11520u);
  EXPECT_EQ(e.next(), 0u);
  EXPECT_EQ(e.next(), 1509978240u);
  EXPECT_EQ(e.next(), 1215971899390074240u);
  // Seeded from one word through mix_seed: a seed is one stream, another seed another.
  Xoshiro256StarStar a(7), b(7), c(8);
  const uint64_t x = a.next();
  EXPECT_EQ(x, b.next());
  EXPECT_NE(x, c.next());
}

TEST(Random, UniformIsTheTop53BitsAndBelowIsMultiplyShift) {
  SplitMixRng r(42);
  SplitMix64 e(42);
  for (int i = 0; i < 100; ++i) {
    const uint64_t bits = e.next();
    const double u = r.uniform();
    EXPECT_EQ(u, static_cast<double>(bits >> 11) * 0x1.0p-53);
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
  SplitMixRng s(3);
  SplitMix64 f(3);
  for (uint64_t n : {1ull, 2ull, 7ull, 1000ull, (1ull << 23) + 5}) {
    const uint64_t bits = f.next();
    const uint64_t k = s.below(n);
    EXPECT_LT(k, n);
    EXPECT_EQ(k, static_cast<uint64_t>((static_cast<unsigned __int128>(bits) * n) >> 64));
  }
}

TEST(Random, ReseedRestartsTheStreamAndDropsTheSpareNormal) {
  XoshiroRng r(5);
  const double first = r.normal();
  r.reseed(5);
  EXPECT_EQ(r.normal(), first);  // not the spare of the first pair
  XoshiroRng fresh(5);
  EXPECT_EQ(fresh.normal(), first);
}

TEST(Random, DrawsHaveTheirDistributions) {
  XoshiroRng r(11);
  const int n = 200000;
  double sum = 0, sum2 = 0, poisson = 0;
  int hits = 0, lo = 0, hi = 0;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal();
    sum += x;
    sum2 += x * x;
    hits += r.bernoulli(0.25);
    const int k = r.uniform_int(-2, 2);
    ASSERT_GE(k, -2);
    ASSERT_LE(k, 2);
    lo += k == -2;
    hi += k == 2;
    poisson += r.poisson(3.0);
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.02);
  EXPECT_NEAR(hits / double(n), 0.25, 0.01);
  EXPECT_NEAR(lo / double(n), 0.2, 0.01);
  EXPECT_NEAR(hi / double(n), 0.2, 0.01);
  EXPECT_NEAR(poisson / n, 3.0, 0.03);
}

TEST(Random, MixSeedSeparatesStreams) {
  EXPECT_NE(mix_seed(1, 0), mix_seed(1, 1));
  EXPECT_NE(mix_seed(1, 0), mix_seed(2, 0));
  EXPECT_EQ(mix_seed(9, 4), splitmix64_mix(9 + kGoldenGamma * 5));
}

}  // namespace
}  // namespace semx::core
