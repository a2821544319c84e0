#include "semx/planner/tour_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace semx::planner {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Local searches the heuristic starts (from the cheapest first legs).
constexpr size_t kStarts = 6;

}  // namespace

double open_path_cost(const TourProblem& p, const std::vector<int>& order) {
  double c = 0.0;
  int prev = 0;
  for (int v : order) {
    c += p.at(prev, v);
    prev = v;
  }
  return c;
}

Tour exact_open_tour(const TourProblem& p, int first) {
  Tour t;
  t.exact = true;
  const int m = p.n - 1;  // nodes to visit, node i + 1 is bit i
  if (m <= 0) return t;
  const size_t states = size_t{1} << m;
  // best[mask * m + j]: the cheapest path from node 0 through the nodes of mask ending at j.
  std::vector<double> best(states * static_cast<size_t>(m), kInf);
  std::vector<int> from(states * static_cast<size_t>(m), -1);
  for (int j = 0; j < m; ++j) {
    if (first >= 1 && j != first - 1) continue;
    best[(size_t{1} << j) * static_cast<size_t>(m) + static_cast<size_t>(j)] = p.at(0, j + 1);
  }
  for (size_t mask = 1; mask < states; ++mask) {
    for (int j = 0; j < m; ++j) {
      if (!(mask >> j & 1u)) continue;
      const double c = best[mask * static_cast<size_t>(m) + static_cast<size_t>(j)];
      if (c == kInf) continue;
      for (int k = 0; k < m; ++k) {
        if (mask >> k & 1u) continue;
        const size_t next = (mask | (size_t{1} << k)) * static_cast<size_t>(m) + static_cast<size_t>(k);
        const double d = c + p.at(j + 1, k + 1);
        if (d < best[next]) {
          best[next] = d;
          from[next] = j;
        }
      }
    }
  }
  const size_t full = states - 1;
  int end = -1;
  double cost = kInf;
  for (int j = 0; j < m; ++j) {
    const double c = best[full * static_cast<size_t>(m) + static_cast<size_t>(j)];
    if (c < cost) cost = c, end = j;
  }
  if (end < 0) return t;
  size_t mask = full;
  for (int j = end; j >= 0;) {
    t.order.push_back(j + 1);
    const int prev = from[mask * static_cast<size_t>(m) + static_cast<size_t>(j)];
    mask &= ~(size_t{1} << j);
    j = prev;
  }
  std::reverse(t.order.begin(), t.order.end());
  t.cost = cost;
  return t;
}

namespace {

// Nearest neighbour from node 0 through `first`, then 2-opt and Or-opt moves until none improves.
Tour improved_from(const TourProblem& p, int first, bool fixed_first) {
  Tour t;
  const int n = p.n;
  // Nearest neighbour from the start (through `first` when given).
  std::vector<bool> used(static_cast<size_t>(n), false);
  used[0] = true;
  int cur = 0;
  if (first >= 1) {
    t.order.push_back(first);
    used[static_cast<size_t>(first)] = true;
    cur = first;
  }
  while (static_cast<int>(t.order.size()) < n - 1) {
    int next = -1;
    for (int j = 1; j < n; ++j) {
      if (!used[static_cast<size_t>(j)] && (next < 0 || p.at(cur, j) < p.at(cur, next))) next = j;
    }
    t.order.push_back(next);
    used[static_cast<size_t>(next)] = true;
    cur = next;
  }
  // Local moves on the order, each kept when it lowers the cost (costs are asymmetric, so a move
  // is valued by the whole path it makes; O(n) per move, O(n^3) per pass, n a few dozen here).
  const int lo = fixed_first ? 1 : 0;  // a forced first node stays first
  const int len = static_cast<int>(t.order.size());
  double cost = open_path_cost(p, t.order);
  std::vector<int> trial;
  for (int pass = 0; pass < 50; ++pass) {
    bool improved = false;
    // 2-opt: reverse order[i..j].
    for (int i = lo; i < len - 1; ++i) {
      for (int j = i + 1; j < len; ++j) {
        trial = t.order;
        std::reverse(trial.begin() + i, trial.begin() + j + 1);
        const double c = open_path_cost(p, trial);
        if (c < cost - 1e-9) {
          t.order.swap(trial);
          cost = c;
          improved = true;
        }
      }
    }
    // Or-opt: move a run of 1-3 nodes elsewhere, in its own direction.
    for (int run = 1; run <= 3; ++run) {
      for (int i = lo; i + run <= len; ++i) {
        for (int to = lo; to <= len - run; ++to) {
          if (to == i) continue;
          trial = t.order;
          std::vector<int> seg(trial.begin() + i, trial.begin() + i + run);
          trial.erase(trial.begin() + i, trial.begin() + i + run);
          trial.insert(trial.begin() + to, seg.begin(), seg.end());
          const double c = open_path_cost(p, trial);
          if (c < cost - 1e-9) {
            t.order.swap(trial);
            cost = c;
            improved = true;
          }
        }
      }
    }
    if (!improved) break;
  }
  t.cost = cost;
  return t;
}

}  // namespace

Tour heuristic_open_tour(const TourProblem& p, int first) {
  if (p.n <= 1) return Tour();
  if (first >= 1) return improved_from(p, first, true);
  // A few starts (the cheapest first legs, each then free to move): local search from one start
  // stayed 25 % above the optimum on random asymmetric costs; the best of six, within ~10 %.
  std::vector<int> starts;
  for (int j = 1; j < p.n; ++j) starts.push_back(j);
  std::stable_sort(starts.begin(), starts.end(), [&](int a, int b) { return p.at(0, a) < p.at(0, b); });
  starts.resize(std::min<size_t>(starts.size(), kStarts));
  Tour best;
  best.cost = kInf;
  for (int s : starts) {
    Tour t = improved_from(p, s, false);
    if (t.cost < best.cost - 1e-12) best = std::move(t);
  }
  return best;
}

Tour solve_open_tour(const TourProblem& p, int exact_max, int first) {
  if (p.n - 1 <= exact_max) return exact_open_tour(p, first);
  return heuristic_open_tour(p, first);
}

Tour solve_tour(const std::vector<std::vector<double>>& cost, int exact_max) {
  TourProblem p;
  p.n = static_cast<int>(cost.size());
  p.cost.reserve(static_cast<std::size_t>(p.n) * static_cast<std::size_t>(p.n));
  for (const auto& row : cost) p.cost.insert(p.cost.end(), row.begin(), row.end());
  Tour t = p.n > 1 ? solve_open_tour(p, exact_max) : Tour{};
  if (p.n <= 1) t.exact = true;
  t.order.insert(t.order.begin(), 0);
  return t;
}

double latency_cost(const TourProblem& p, const std::vector<int>& order, const std::vector<double>& weight) {
  double t = 0.0, sum = 0.0;
  int at = 0;
  for (const int v : order) {
    t += p.at(at, v);
    sum += weight[static_cast<std::size_t>(v)] * t;
    at = v;
  }
  return sum;
}

double quota_time(const TourProblem& p, const std::vector<int>& order, const std::vector<double>& weight,
                  double share) {
  double total = 0.0;
  for (const int v : order) total += weight[static_cast<std::size_t>(v)];
  if (!(total > 0)) return 0.0;
  double t = 0.0, seen = 0.0;
  int at = 0;
  for (const int v : order) {
    t += p.at(at, v);
    seen += weight[static_cast<std::size_t>(v)];
    at = v;
    // A relative tolerance: the shares of a tour's weights summed in another order must agree.
    if (seen >= share * total * (1.0 - 1e-12)) break;
  }
  return t;
}

int highest_rate_node(const TourProblem& p, const std::vector<double>& weight) {
  int best = -1;
  double best_rate = -1.0;
  for (int v = 1; v < p.n; ++v) {
    // A leg under a millisecond is a site the vehicle is at: it outranks every site farther away.
    const double rate = weight[static_cast<std::size_t>(v)] / std::max(p.at(0, v), 1e-3);
    if (rate > best_rate) best_rate = rate, best = v;
  }
  return best;
}

double tour_cost(const std::vector<std::vector<double>>& cost, const std::vector<int>& order) {
  double c = 0.0;
  for (std::size_t i = 1; i < order.size(); ++i)
    c += cost[static_cast<std::size_t>(order[i - 1])][static_cast<std::size_t>(order[i])];
  return c;
}

std::vector<int> improve_order(std::vector<int> order,
                               const std::function<double(const std::vector<int>&)>& objective,
                               int max_evaluations, bool may_drop) {
  int evaluations = 1;
  double best = objective(order);
  // Tries a candidate order; keeps it when it is better.
  auto better = [&](std::vector<int>&& cand) {
    if (evaluations >= max_evaluations) return false;
    ++evaluations;
    const double v = objective(cand);
    if (v < best - 1e-9) {
      best = v;
      order = std::move(cand);
      return true;
    }
    return false;
  };
  bool improved = true;
  while (improved && evaluations < max_evaluations) {
    improved = false;
    const size_t n = order.size();
    if (may_drop)
      for (size_t i = 0; i < order.size() && !improved; ++i) {
        std::vector<int> c = order;
        c.erase(c.begin() + static_cast<std::ptrdiff_t>(i));
        improved = better(std::move(c));
      }
    for (size_t len = 1; len <= 3 && !improved; ++len)
      for (size_t i = 0; i + len <= n && !improved; ++i) {
        // The segment [i, i + len) moved to before position j of what is left.
        std::vector<int> seg(order.begin() + static_cast<std::ptrdiff_t>(i),
                             order.begin() + static_cast<std::ptrdiff_t>(i + len));
        std::vector<int> rest = order;
        rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(i),
                   rest.begin() + static_cast<std::ptrdiff_t>(i + len));
        for (size_t j = 0; j <= rest.size() && !improved; ++j) {
          if (j == i) continue;
          std::vector<int> c = rest;
          c.insert(c.begin() + static_cast<std::ptrdiff_t>(j), seg.begin(), seg.end());
          improved = better(std::move(c));
        }
      }
    for (size_t i = 0; i + 1 < n && !improved; ++i)
      for (size_t j = i + 2; j <= n && !improved; ++j) {
        std::vector<int> c = order;
        std::reverse(c.begin() + static_cast<std::ptrdiff_t>(i), c.begin() + static_cast<std::ptrdiff_t>(j));
        improved = better(std::move(c));
      }
  }
  return order;
}

std::vector<int> improve_order_within(const std::vector<int>& order, const TwoTimes& times,
                                      int max_evaluations, double first_cap) {
  return improve_order(
      order,
      [&](const std::vector<int>& o) {
        const auto [first, second] = times(o, false);
        return first > first_cap ? std::numeric_limits<double>::infinity() : second;
      },
      max_evaluations, true);
}

int nearest_best_of_both(const std::vector<std::pair<double, double>>& times) {
  double first = std::numeric_limits<double>::infinity(), second = first;
  for (const auto& [a, b] : times) first = std::min(first, a), second = std::min(second, b);
  // A column never finite ranks every pair alike on it; an infinite time against a finite best
  // ranks last.
  auto ratio = [](double x, double lowest) {
    if (!std::isfinite(lowest)) return 1.0;
    return std::isfinite(x) ? x / std::max(lowest, 1e-9) : std::numeric_limits<double>::infinity();
  };
  int best = -1;
  double best_worse = 0.0, best_sum = 0.0;
  for (size_t i = 0; i < times.size(); ++i) {
    const double worse = std::max(ratio(times[i].first, first), ratio(times[i].second, second));
    const double sum = times[i].first + times[i].second;
    if (best < 0 || worse < best_worse - 1e-9 || (worse < best_worse + 1e-9 && sum < best_sum - 1e-9)) {
      best = static_cast<int>(i);
      best_worse = worse;
      best_sum = sum;
    }
  }
  return best;
}

}  // namespace semx::planner
