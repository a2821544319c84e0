// The order in which the known-map oracle (oracle_strategy.hpp) flies its viewpoints: an open
// tour (a path, no return) from node 0, the vehicle, through every other node, minimising the
// summed cost, cost[i][j] being the travel time from i to j (need not be symmetric).
//
// Up to `exact_max` nodes besides the start it is solved exactly (Held-Karp dynamic programming
// over subsets, O(2^n n^2)); beyond, nearest neighbour, then 2-opt (reverse a stretch) and Or-opt
// (move a stretch of 1-3 nodes elsewhere, either way round) until neither finds a better tour.
#pragma once

#include <vector>

namespace semx::planner {

struct Tour {
  std::vector<int> order;  // order[0] == 0; every node once
  double cost = 0.0;
  bool exact = false;      // solved by the dynamic programme
};

Tour solve_tour(const std::vector<std::vector<double>>& cost, int exact_max);
// Summed cost of an order (consecutive pairs).
double tour_cost(const std::vector<std::vector<double>>& cost, const std::vector<int>& order);

}  // namespace semx::planner
