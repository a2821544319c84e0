// The global tour of FUEL (Zhou et al. 2021, §V-A): an asymmetric travelling-salesman problem over
// the vehicle's pose (node 0) and one viewpoint per frontier cluster (nodes 1..n-1), with every
// return to node 0 free, so the cheapest closed tour is the cheapest open path from the vehicle
// through every viewpoint. FUEL hands the matrix to LKH; here tours over at most `exact_max`
// viewpoints are solved exactly (Held-Karp dynamic programming, 2^m m^2 steps: 0.6 M at m = 12),
// larger ones by nearest neighbour then 2-opt and Or-opt moves until none improves.
#pragma once

#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

namespace semx::planner {

// cost[i * n + j]: travel cost from node i to node j (the diagonal and column 0 are ignored).
struct TourProblem {
  int n = 0;  // nodes, the start included
  std::vector<double> cost;
  double at(int i, int j) const {
    return cost[static_cast<std::size_t>(i) * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)];
  }
};

struct Tour {
  std::vector<int> order;  // nodes 1..n-1 in visiting order
  double cost = 0.0;       // of the open path 0 -> order[0] -> ... -> order.back()
  bool exact = false;      // solved by dynamic programming (optimal)
};

// The cost of visiting `order` from node 0.
double open_path_cost(const TourProblem& p, const std::vector<int>& order);
// The weighted latency of visiting `order` from node 0: the sum over its nodes of weight[node]
// times the cost of the path up to that node (what a tour that should see the most soonest
// minimises, where open_path_cost is the time to see everything).
double latency_cost(const TourProblem& p, const std::vector<int>& order, const std::vector<double>& weight);
// The cost of the path up to the node of `order` at which the visited nodes' weight first reaches
// `share` of the weight of all of `order`'s nodes (0 for an empty order or no weight): the time a
// tour takes to show that share, which the weighted latency only approximates.
double quota_time(const TourProblem& p, const std::vector<int>& order, const std::vector<double>& weight,
                  double share);
// The node (1..n-1) of the highest rate weight[node] / cost from node 0 (a greedy planner's next
// goal: the most seen per second of flight), the first of equals; -1 when there is none.
int highest_rate_node(const TourProblem& p, const std::vector<double>& weight);
// The best open tour; with `first` >= 1 the tour must visit that node first.
Tour solve_open_tour(const TourProblem& p, int exact_max, int first = -1);
// The two methods on their own (tests compare them with brute force).
Tour exact_open_tour(const TourProblem& p, int first = -1);
Tour heuristic_open_tour(const TourProblem& p, int first = -1);

// The same on a square matrix cost[i][j], the order starting with node 0 (the known-map oracle's
// form: it keeps the matrix to fly and report the tour).
Tour solve_tour(const std::vector<std::vector<double>>& cost, int exact_max);
// The summed cost of consecutive pairs of `order`.
double tour_cost(const std::vector<std::vector<double>>& cost, const std::vector<int>& order);

// Local search on the order of a route's stops for an objective only the caller can evaluate
// (the known-map oracle: the modelled time at which the stops have shown a quota of T, which a
// shortest tour does not minimise: it may leave the largest view for last). Moves, first
// improvement, until none improves or `max_evaluations` objectives were asked for: a segment of
// 1-3 stops moved elsewhere (Or-opt), a segment reversed (2-opt), and with `may_drop` a stop
// removed. Lower is better; the result is never worse than `order`.
std::vector<int> improve_order(std::vector<int> order,
                               const std::function<double(const std::vector<int>&)>& objective,
                               int max_evaluations, bool may_drop);

// Two times of an order, e.g. the oracle model's times to 85 % and to 95 % of T (infinite when
// never). With `first_only` the caller may stop once the first is known and leave the second
// infinite.
using TwoTimes = std::function<std::pair<double, double>(const std::vector<int>&, bool first_only)>;
// improve_order for the second time among the orders whose first time is at most `first_cap`
// (an order above it is never taken): a schedule chosen for the sum of the two times gives up much
// of the first (env3's oracle reached 85 % at 69 s where 47 s can be had).
std::vector<int> improve_order_within(const std::vector<int>& order, const TwoTimes& times,
                                      int max_evaluations, double first_cap);
// Of (first, second) time pairs, the index of the one nearest the best of both: the lowest of its
// worse ratio to the lowest first and to the lowest second time, ties by the sum; -1 when empty.
int nearest_best_of_both(const std::vector<std::pair<double, double>>& times);

}  // namespace semx::planner
