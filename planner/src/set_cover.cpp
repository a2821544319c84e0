#include "semx/planner/set_cover.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <stdexcept>
#include <tuple>

namespace semx::planner {

CoverResult greedy_cover(CoverSource& source, int32_t num_elements, double fraction,
                         const std::vector<uint8_t>* already) {
  CoverResult r;
  const int groups = source.groups(), members = source.members();
  if (members < 1 || members > 32) throw std::invalid_argument("greedy_cover: 1-32 members per group");
  if (already && already->size() != static_cast<size_t>(num_elements))
    throw std::invalid_argument("greedy_cover: one covered flag per element");
  std::vector<uint8_t> covered = already ? *already : std::vector<uint8_t>(static_cast<size_t>(num_elements), 0);
  std::vector<uint8_t> observable(covered.size(), 0);
  // bound[g * members + m]: the gain of set (g, m) when last evaluated, an upper bound of it now.
  std::vector<int64_t> bound(static_cast<size_t>(groups) * members, 0);
  std::vector<int64_t> fresh(static_cast<size_t>(groups), -1);  // round of the group's last evaluation
  std::vector<MaskedElement> els;
  std::vector<int64_t> gains(static_cast<size_t>(members));
  auto evaluate = [&](int g) {
    source.elements(g, els);
    ++r.evaluations;
    std::fill(gains.begin(), gains.end(), 0);
    for (const MaskedElement& e : els) {
      if (covered[static_cast<size_t>(e.element)]) continue;
      for (uint32_t m = e.members; m; m &= m - 1) ++gains[static_cast<size_t>(__builtin_ctz(m))];
    }
  };
  // Max-heap of (bound, -group, -member): ties go to the lower group, then member, so the result
  // does not depend on the heap's internals.
  using Entry = std::tuple<int64_t, int, int>;
  std::priority_queue<Entry> heap;
  for (int g = 0; g < groups; ++g) {
    evaluate(g);
    for (const MaskedElement& e : els) {
      if (e.members && !observable[static_cast<size_t>(e.element)]) {
        observable[static_cast<size_t>(e.element)] = 1;
        ++r.observable;
        r.covered += covered[static_cast<size_t>(e.element)];
      }
    }
    fresh[static_cast<size_t>(g)] = 0;
    for (int m = 0; m < members; ++m) {
      bound[static_cast<size_t>(g) * members + m] = gains[static_cast<size_t>(m)];
      if (gains[static_cast<size_t>(m)] > 0) heap.emplace(gains[static_cast<size_t>(m)], -g, -m);
    }
  }
  r.required = static_cast<int64_t>(std::ceil(fraction * static_cast<double>(r.observable) - 1e-9));
  int64_t round = 0;
  while (r.covered < r.required && !heap.empty()) {
    const auto [gain, ng, nm] = heap.top();
    heap.pop();
    const int g = -ng, m = -nm;
    const size_t slot = static_cast<size_t>(g) * members + m;
    if (gain != bound[slot] || gain <= 0) continue;  // an older entry of a set evaluated since
    if (fresh[static_cast<size_t>(g)] != round) {
      evaluate(g);
      fresh[static_cast<size_t>(g)] = round;
      for (int k = 0; k < members; ++k) {
        const size_t s = static_cast<size_t>(g) * members + k;
        // An unchanged bound's entry is still in the heap (but the one just popped).
        if (k != m && gains[static_cast<size_t>(k)] == bound[s]) continue;
        bound[s] = gains[static_cast<size_t>(k)];
        if (bound[s] > 0) heap.emplace(bound[s], -g, -k);
      }
      continue;  // exact now: it comes first again only if it is still the best
    }
    // Exact this round and the best bound left: the greedy's pick.
    source.elements(g, els);
    ++r.evaluations;
    int64_t got = 0;
    for (const MaskedElement& e : els) {
      if ((e.members >> m & 1u) && !covered[static_cast<size_t>(e.element)]) {
        covered[static_cast<size_t>(e.element)] = 1;
        ++got;
      }
    }
    r.covered += got;
    r.picks.push_back({g, m, got});
    bound[slot] = 0;
    ++round;
  }
  // Redundant picks: how many picks hold each element; a pick whose elements are all held by
  // others too, or whose own ones the required share can spare, goes.
  // Elements covered before the first pick are held by something no pick is: never lost.
  std::vector<uint16_t> holders(covered.size(), 0);
  if (already)
    for (size_t e = 0; e < covered.size(); ++e)
      if ((*already)[e]) holders[e] = 1;
  std::vector<std::vector<int32_t>> own(r.picks.size());
  for (size_t i = 0; i < r.picks.size(); ++i) {
    source.elements(r.picks[i].group, els);
    ++r.evaluations;
    for (const MaskedElement& e : els) {
      if (e.members >> r.picks[i].member & 1u) {
        own[i].push_back(e.element);
        if (holders[static_cast<size_t>(e.element)] < UINT16_MAX) ++holders[static_cast<size_t>(e.element)];
      }
    }
  }
  std::vector<bool> keep(r.picks.size(), true);
  for (size_t i = r.picks.size(); i-- > 0;) {
    int64_t loss = 0;
    for (int32_t e : own[i]) loss += holders[static_cast<size_t>(e)] == 1;
    if (r.covered - loss < r.required) continue;
    keep[i] = false;
    r.covered -= loss;
    ++r.dropped;
    for (int32_t e : own[i]) --holders[static_cast<size_t>(e)];
  }
  std::vector<CoverPick> kept;
  for (size_t i = 0; i < r.picks.size(); ++i)
    if (keep[i]) kept.push_back(r.picks[i]);
  r.picks = std::move(kept);
  return r;
}

ListCoverSource::ListCoverSource(std::vector<std::vector<std::vector<int32_t>>> sets) : sets_(std::move(sets)) {
  members_ = 1;
  for (const auto& g : sets_) members_ = std::max(members_, static_cast<int>(g.size()));
  if (members_ > 32) throw std::invalid_argument("ListCoverSource: at most 32 members per group");
}

void ListCoverSource::elements(int group, std::vector<MaskedElement>& out) {
  std::map<int32_t, uint32_t> masks;
  const auto& g = sets_[static_cast<size_t>(group)];
  for (size_t m = 0; m < g.size(); ++m)
    for (int32_t e : g[m]) masks[e] |= 1u << m;
  out.clear();
  for (const auto& [e, mask] : masks) out.push_back({e, mask});
}

}  // namespace semx::planner
