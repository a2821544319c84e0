#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "semx/core/queue_key.hpp"

using semx::core::queue_key;
using semx::core::queue_key_cost;
using semx::core::queue_key_index;

TEST(QueueKey, OrdersAsTheCostIndexPair) {
  // Costs as a search makes them: equal ones (ties go to the index), neighbours a float step
  // apart, zero, and spread over many magnitudes.
  std::mt19937_64 rng(11);
  std::vector<float> costs{0.0f, 0.2f, 0.2f, std::nextafter(0.2f, 1.0f), 1.0f, 1e-30f, 3.4e38f};
  std::uniform_real_distribution<float> u(0.0f, 50.0f);
  for (int i = 0; i < 200; ++i) costs.push_back(u(rng));
  std::vector<uint32_t> indices{0u, 1u, 2u, 1000u, 0x7fffffffu, 0xffffffffu};
  for (int i = 0; i < 20; ++i) indices.push_back(static_cast<uint32_t>(rng()));
  std::vector<std::pair<float, uint32_t>> entries;
  for (size_t i = 0; i < costs.size(); ++i) entries.emplace_back(costs[i], indices[i % indices.size()]);
  for (const auto& a : entries) {
    EXPECT_EQ(queue_key_cost(queue_key(a.first, a.second)), a.first);
    EXPECT_EQ(queue_key_index(queue_key(a.first, a.second)), a.second);
    for (const auto& b : entries) {
      ASSERT_EQ(queue_key(a.first, a.second) < queue_key(b.first, b.second), a < b)
          << "(" << a.first << ", " << a.second << ") against (" << b.first << ", " << b.second << ")";
    }
  }
}
