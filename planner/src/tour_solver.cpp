#include "semx/planner/tour_solver.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace semx::planner {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// An improvement must beat this, so rounding cannot make 2-opt and Or-opt cycle.
constexpr double kEps = 1e-9;

Tour held_karp(const std::vector<std::vector<double>>& c) {
  const int n = static_cast<int>(c.size()) - 1;  // nodes besides the start: 1..n, bit i-1
  const size_t full = (size_t{1} << n) - 1;
  // best[S][j]: cheapest path from 0 through exactly the nodes of S, ending at j (in S).
  std::vector<double> best((full + 1) * static_cast<size_t>(n), kInf);
  std::vector<int8_t> prev(best.size(), -1);
  for (int j = 0; j < n; ++j) best[(size_t{1} << j) * n + j] = c[0][static_cast<size_t>(j + 1)];
  for (size_t s = 1; s <= full; ++s) {
    for (int j = 0; j < n; ++j) {
      if (!(s >> j & 1)) continue;
      const double here = best[s * n + j];
      if (here == kInf) continue;
      for (int k = 0; k < n; ++k) {
        if (s >> k & 1) continue;
        const size_t t = s | (size_t{1} << k);
        const double v = here + c[static_cast<size_t>(j + 1)][static_cast<size_t>(k + 1)];
        if (v < best[t * n + k]) {
          best[t * n + k] = v;
          prev[t * n + k] = static_cast<int8_t>(j);
        }
      }
    }
  }
  Tour t;
  t.exact = true;
  int end = 0;
  for (int j = 1; j < n; ++j)
    if (best[full * n + j] < best[full * n + end]) end = j;
  t.cost = best[full * n + end];
  std::vector<int> rev;
  size_t s = full;
  for (int j = end; j >= 0;) {
    rev.push_back(j + 1);
    const int p = prev[s * n + j];
    s &= ~(size_t{1} << j);
    j = p;
  }
  t.order.push_back(0);
  t.order.insert(t.order.end(), rev.rbegin(), rev.rend());
  return t;
}

// 2-opt on an open path: reversing order[i..j] (1 <= i < j) replaces the edges into i and out of
// j, and turns the stretch around (its cost each way from prefix sums).
bool two_opt(const std::vector<std::vector<double>>& c, std::vector<int>& o) {
  const size_t n = o.size();
  std::vector<double> fwd(n, 0.0), bwd(n, 0.0);  // fwd[k]: cost of o[0..k] forward; bwd the reverse edges
  for (size_t k = 1; k < n; ++k) {
    fwd[k] = fwd[k - 1] + c[static_cast<size_t>(o[k - 1])][static_cast<size_t>(o[k])];
    bwd[k] = bwd[k - 1] + c[static_cast<size_t>(o[k])][static_cast<size_t>(o[k - 1])];
  }
  for (size_t i = 1; i + 1 < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const auto a = static_cast<size_t>(o[i - 1]), b = static_cast<size_t>(o[i]);
      const auto d = static_cast<size_t>(o[j]);
      double before = c[a][b] + (fwd[j] - fwd[i]);
      double after = c[a][d] + (bwd[j] - bwd[i]);
      if (j + 1 < n) {
        const auto e = static_cast<size_t>(o[j + 1]);
        before += c[d][e];
        after += c[b][e];
      }
      if (after < before - kEps) {
        std::reverse(o.begin() + static_cast<long>(i), o.begin() + static_cast<long>(j) + 1);
        return true;
      }
    }
  }
  return false;
}

// Or-opt: take the stretch o[i..i+len-1] out and put it, forward or reversed, between two other
// consecutive nodes (or at the end).
bool or_opt(const std::vector<std::vector<double>>& c, std::vector<int>& o) {
  const size_t n = o.size();
  for (size_t len = 1; len <= 3; ++len) {
    for (size_t i = 1; i + len <= n; ++i) {
      std::vector<int> rest;
      rest.reserve(n - len);
      rest.insert(rest.end(), o.begin(), o.begin() + static_cast<long>(i));
      rest.insert(rest.end(), o.begin() + static_cast<long>(i + len), o.end());
      const std::vector<int> seg(o.begin() + static_cast<long>(i), o.begin() + static_cast<long>(i + len));
      const double now = tour_cost(c, o);
      const double base = tour_cost(c, rest);
      double inner_f = 0, inner_b = 0;
      for (size_t k = 0; k + 1 < seg.size(); ++k) {
        inner_f += c[static_cast<size_t>(seg[k])][static_cast<size_t>(seg[k + 1])];
        inner_b += c[static_cast<size_t>(seg[k + 1])][static_cast<size_t>(seg[k])];
      }
      // Insert after rest[p] (p from 0: never before the start).
      for (size_t p = 0; p < rest.size(); ++p) {
        if (p + 1 == i) continue;  // where it came from
        const auto a = static_cast<size_t>(rest[p]);
        const bool last = p + 1 == rest.size();
        const size_t b = last ? 0 : static_cast<size_t>(rest[p + 1]);
        const double removed = last ? 0.0 : c[a][b];
        for (int dir = 0; dir < 2; ++dir) {
          const auto first = static_cast<size_t>(dir ? seg.back() : seg.front());
          const auto end = static_cast<size_t>(dir ? seg.front() : seg.back());
          const double v = base - removed + c[a][first] + (dir ? inner_b : inner_f) + (last ? 0.0 : c[end][b]);
          if (v < now - kEps) {
            std::vector<int> s = seg;
            if (dir) std::reverse(s.begin(), s.end());
            rest.insert(rest.begin() + static_cast<long>(p + 1), s.begin(), s.end());
            o = std::move(rest);
            return true;
          }
        }
      }
    }
  }
  return false;
}

}  // namespace

double tour_cost(const std::vector<std::vector<double>>& cost, const std::vector<int>& order) {
  double s = 0.0;
  for (size_t k = 1; k < order.size(); ++k)
    s += cost[static_cast<size_t>(order[k - 1])][static_cast<size_t>(order[k])];
  return s;
}

Tour solve_tour(const std::vector<std::vector<double>>& cost, int exact_max) {
  const size_t n = cost.size();
  for (const auto& row : cost)
    if (row.size() != n) throw std::invalid_argument("solve_tour: the cost matrix must be square");
  Tour t;
  if (n == 0) return t;
  if (n <= 2) {
    for (size_t i = 0; i < n; ++i) t.order.push_back(static_cast<int>(i));
    t.cost = tour_cost(cost, t.order);
    t.exact = true;
    return t;
  }
  if (static_cast<int>(n) - 1 <= std::min(exact_max, 20)) return held_karp(cost);
  // Nearest neighbour from the start.
  std::vector<bool> used(n, false);
  used[0] = true;
  t.order.push_back(0);
  for (size_t k = 1; k < n; ++k) {
    const auto from = static_cast<size_t>(t.order.back());
    size_t best = n;
    for (size_t j = 0; j < n; ++j)
      if (!used[j] && (best == n || cost[from][j] < cost[from][best])) best = j;
    used[best] = true;
    t.order.push_back(static_cast<int>(best));
  }
  // Each move strictly lowers the cost, so this ends; the cap only bounds pathological inputs.
  for (int it = 0; it < 100000; ++it) {
    if (two_opt(cost, t.order)) continue;
    if (or_opt(cost, t.order)) continue;
    break;
  }
  t.cost = tour_cost(cost, t.order);
  return t;
}

}  // namespace semx::planner
