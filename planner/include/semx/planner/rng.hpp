// The planner's random numbers: a seeded 64-bit generator whose draws are defined bit for bit
// here (no std:: distributions, whose algorithms differ between standard libraries), so a seed
// gives the same roadmap on every platform and every run (DESIGN.md §3).
#pragma once

#include <cstdint>

namespace semx::planner {

class Rng {
 public:
  explicit Rng(uint64_t seed = 1) { reseed(seed); }
  void reseed(uint64_t seed) {
    state_ = seed;
    (void)next();
  }
  // splitmix64 (Steele, Lea & Flood 2014): passes BigCrush, one multiply-xorshift chain per draw.
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1): the top 53 bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [0, n), n > 0 (multiply-shift; bias below 2^-40 for any n < 2^24).
  uint64_t below(uint64_t n) {
    return static_cast<uint64_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
  }

 private:
  uint64_t state_ = 0;
};

}  // namespace semx::planner
