// Seeded random numbers whose every draw is defined bit for bit here (no std:: distributions,
// whose algorithms differ between standard libraries), so a seed gives the same run on every
// platform (DESIGN.md §3).
//
// One set of draws (Random) over two engines. Both engines stay because each stream is part of
// what a seed means: the planner's roadmap is drawn from SplitMix64 (one word of state, cheap to
// reseed per cycle), the simulator's noise and worlds from xoshiro256** (a generator per frame,
// seeded through mix_seed); changing either engine changes every figure of every run.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "semx/core/angles.hpp"
#include "semx/core/byte_io.hpp"

namespace semx::core {

inline constexpr uint64_t kGoldenGamma = 0x9E3779B97F4A7C15ull;

// SplitMix64's output function (Steele, Lea & Flood 2014): a bijective mix of 64 bits.
constexpr uint64_t splitmix64_mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Decorrelates (seed, stream, index) into a fresh seed.
constexpr uint64_t mix_seed(uint64_t a, uint64_t b = 0) { return splitmix64_mix(a + kGoldenGamma * (b + 1)); }

// SplitMix64: passes BigCrush, one multiply-xorshift chain per draw. Seeding discards the first
// draw (the planner's streams have always done so).
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed = 1) { reseed(seed); }
  void reseed(uint64_t seed) {
    state_ = seed;
    (void)next();
  }
  uint64_t next() { return splitmix64_mix(state_ += kGoldenGamma); }
  // The exact state, for a process that saves it and resumes (state_file.hpp).
  void save(ByteWriter& w) const { w.u64(state_); }
  void restore(ByteReader& r) { state_ = r.u64(); }

 private:
  uint64_t state_ = 0;
};

// xoshiro256** (Blackman & Vigna 2018), its four words seeded by a chain of mix_seed.
class Xoshiro256StarStar {
 public:
  explicit Xoshiro256StarStar(uint64_t seed = 1) { reseed(seed); }
  // From the four words themselves (the reference implementation's test vectors).
  explicit Xoshiro256StarStar(const std::array<uint64_t, 4>& state)
      : s_{state[0], state[1], state[2], state[3]} {}
  void reseed(uint64_t seed) {
    uint64_t x = seed;
    for (auto& s : s_) {
      x = mix_seed(x, 0x5eed);
      s = x;
    }
  }
  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  void save(ByteWriter& w) const {
    for (uint64_t s : s_) w.u64(s);
  }
  void restore(ByteReader& r) {
    for (uint64_t& s : s_) s = r.u64();
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

template <class Engine>
class Random {
 public:
  explicit Random(uint64_t seed = 1) : engine_(seed) {}
  void reseed(uint64_t seed) {
    engine_.reseed(seed);
    has_spare_ = false;
  }
  uint64_t next() { return engine_.next(); }
  // Uniform in [0, 1): the top 53 bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [0, n), n > 0 (multiply-shift; bias below 2^-40 for any n < 2^24).
  uint64_t below(uint64_t n) {
    return static_cast<uint64_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
  }
  // Uniform integer in [lo, hi].
  int uniform_int(int lo, int hi) {
    return lo + static_cast<int>(uniform() * (static_cast<double>(hi) - lo + 1.0));
  }
  bool bernoulli(double p) { return uniform() < p; }
  // Standard normal (Box-Muller, caching the second value).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }
  // Poisson with small mean (Knuth).
  int poisson(double mean) {
    const double limit = std::exp(-mean);
    int k = 0;
    double p = uniform();
    while (p > limit) {
      ++k;
      p *= uniform();
    }
    return k;
  }
  // Every draw after restore() is the one the saved generator would have made next.
  void save(ByteWriter& w) const {
    engine_.save(w);
    w.f64(spare_);
    w.u8(has_spare_ ? 1 : 0);
  }
  void restore(ByteReader& r) {
    engine_.restore(r);
    spare_ = r.f64();
    has_spare_ = r.u8() != 0;
  }

 private:
  Engine engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// The planner's generator (one word of state) and the simulator's.
using SplitMixRng = Random<SplitMix64>;
using XoshiroRng = Random<Xoshiro256StarStar>;

}  // namespace semx::core
