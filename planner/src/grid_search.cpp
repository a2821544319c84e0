#include "semx/planner/grid_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr double kInf = std::numeric_limits<double>::infinity();

int32_t floor_div(int32_t v, int32_t s) { return v >= 0 ? v / s : -((-v + s - 1) / s); }

// The 26 steps, each with its length in cells and the cells it cuts across (the steps along a
// proper subset of its axes), so a diagonal step cannot slip between two blocked cells.
struct Step {
  VoxelKey d;
  double length = 0.0;
  std::vector<VoxelKey> across;
};

const std::vector<Step>& steps() {
  static const std::vector<Step> s = [] {
    std::vector<Step> out;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          Step st;
          st.d = {dx, dy, dz};
          st.length = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          for (int mask = 1; mask < 7; ++mask) {
            const VoxelKey sub{(mask & 1) ? dx : 0, (mask & 2) ? dy : 0, (mask & 4) ? dz : 0};
            if (sub == st.d || sub == VoxelKey{0, 0, 0}) continue;
            if ((dx == 0 && sub.x) || (dy == 0 && sub.y) || (dz == 0 && sub.z)) continue;
            if (std::find(st.across.begin(), st.across.end(), sub) == st.across.end()) st.across.push_back(sub);
          }
          out.push_back(st);
        }
    return out;
  }();
  return s;
}

uint64_t pack(const VoxelKey& k) {
  return map::pack_block(k);  // 21 bits per axis: any lattice coordinate of a valid key
}

}  // namespace

int64_t GridSearch::Lattice::index(const VoxelKey& l) const {
  const int x = l.x - origin.x, y = l.y - origin.y, z = l.z - origin.z;
  if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return -1;
  return x + static_cast<int64_t>(nx) * (y + static_cast<int64_t>(ny) * z);
}

VoxelKey GridSearch::Lattice::coords(int64_t i) const {
  const int64_t x = i % nx, yz = i / nx;
  return {origin.x + static_cast<int32_t>(x), origin.y + static_cast<int32_t>(yz % ny),
          origin.z + static_cast<int32_t>(yz / ny)};
}

GridSearch::GridSearch(const CollisionChecker& checker, const CollisionConfig& collision, int step,
                       double low_penalty)
    : checker_(checker), collision_(collision), low_penalty_(low_penalty) {
  coarse_.stride = std::max(1, step);
  fine_.stride = 1;
}

void GridSearch::reset() {
  for (Lattice* l : {&coarse_, &fine_}) {
    const int stride = l->stride;
    *l = Lattice();
    l->stride = stride;
  }
  dirty_coarse_.clear();
  dirty_fine_.clear();
  tree_valid_ = false;
}

void GridSearch::set_grid(const map::StateGrid* grid) {
  if (grid == grid_) return;
  grid_ = grid;
  reset();
}

void GridSearch::note_changes(const std::vector<map::VoxelChange>& changes) {
  for (const map::VoxelChange& c : changes) {
    const VoxelKey b = map::block_of(c.key);
    dirty_coarse_.insert(b);
    dirty_fine_.insert(b);
  }
}

VoxelKey GridSearch::lattice_of(const Lattice& l, const Eigen::Vector3d& p) const {
  const VoxelKey v = grid_->keys().key(p);
  return {floor_div(v.x, l.stride), floor_div(v.y, l.stride), floor_div(v.z, l.stride)};
}

Eigen::Vector3d GridSearch::point(const Lattice& l, const VoxelKey& c) const {
  const double res = grid_->resolution(), h = 0.5 * l.stride;
  return {(c.x * l.stride + h) * res, (c.y * l.stride + h) * res, (c.z * l.stride + h) * res};
}

void GridSearch::prepare(Lattice& l) {
  const double res = grid_->resolution();
  // The fine lattice keeps what a passage node keeps; the coarse one half a cell less (header).
  l.threshold = l.stride == 1 ? collision_.door_clearance
                              : collision_.door_clearance - 0.5 * l.stride * res;
  std::set<VoxelKey>& dirty = &l == &coarse_ ? dirty_coarse_ : dirty_fine_;
  const map::KeyBox& kb = grid_->known_bounds();
  if (kb.empty()) {
    dirty.clear();
    return;
  }
  const VoxelKey lo{floor_div(kb.min.x, l.stride), floor_div(kb.min.y, l.stride), floor_div(kb.min.z, l.stride)};
  const VoxelKey hi{floor_div(kb.max.x, l.stride), floor_div(kb.max.y, l.stride), floor_div(kb.max.z, l.stride)};
  const bool fits = l.nx > 0 && lo.x >= l.origin.x && lo.y >= l.origin.y && lo.z >= l.origin.z &&
                    hi.x < l.origin.x + l.nx && hi.y < l.origin.y + l.ny && hi.z < l.origin.z + l.nz;
  if (!fits) {
    // Grow with room to spare (about 2 m horizontally, 0.8 m vertically), keeping what is cached.
    const int mxy = std::max(2, static_cast<int>(std::ceil(2.0 / (res * l.stride))));
    const int mz = std::max(1, static_cast<int>(std::ceil(0.8 / (res * l.stride))));
    VoxelKey nlo{lo.x - mxy, lo.y - mxy, lo.z - mz}, nhi{hi.x + mxy, hi.y + mxy, hi.z + mz};
    if (l.nx > 0) {
      nlo = {std::min(nlo.x, l.origin.x), std::min(nlo.y, l.origin.y), std::min(nlo.z, l.origin.z)};
      nhi = {std::max(nhi.x, l.origin.x + l.nx - 1), std::max(nhi.y, l.origin.y + l.ny - 1),
             std::max(nhi.z, l.origin.z + l.nz - 1)};
    }
    Lattice n;
    n.stride = l.stride;
    n.threshold = l.threshold;
    n.origin = nlo;
    n.nx = nhi.x - nlo.x + 1;
    n.ny = nhi.y - nlo.y + 1;
    n.nz = nhi.z - nlo.z + 1;
    const size_t cells = static_cast<size_t>(n.nx) * static_cast<size_t>(n.ny) * static_cast<size_t>(n.nz);
    n.cls.assign(cells, kUnset);
    // The old box lies inside the new one: copy it row by row.
    const size_t ox = static_cast<size_t>(l.origin.x - n.origin.x);
    for (int z = 0; z < l.nz; ++z)
      for (int y = 0; y < l.ny; ++y) {
        const size_t src = static_cast<size_t>(l.nx) * (static_cast<size_t>(y) + static_cast<size_t>(l.ny) * z);
        const size_t dst = static_cast<size_t>(n.nx) * (static_cast<size_t>(y + l.origin.y - n.origin.y) +
                                                        static_cast<size_t>(n.ny) * (z + l.origin.z - n.origin.z)) +
                           ox;
        std::copy(l.cls.begin() + static_cast<long>(src), l.cls.begin() + static_cast<long>(src + l.nx),
                  n.cls.begin() + static_cast<long>(dst));
      }
    n.g.assign(cells, kInfF);
    n.parent.assign(cells, -1);
    n.stamp.assign(cells, 0);
    n.closed.assign(cells, 0);
    l = std::move(n);
    if (&l == &coarse_) tree_valid_ = false;
  }
  for (const VoxelKey& b : dirty) invalidate(l, b);
  dirty.clear();
}

void GridSearch::invalidate(Lattice& l, const VoxelKey& block) {
  // A voxel changes the ESDF of centres within the checker's cap, and a cell reads the 8 centres
  // around its point: everything within cap + a cell of the block's voxels.
  const double res = grid_->resolution();
  const int r = static_cast<int>(std::ceil((checker_.cached_cap() + (l.stride + 1) * res) / res));
  const VoxelKey v0{block.x * map::kBlockSize - r, block.y * map::kBlockSize - r, block.z * map::kBlockSize - r};
  const VoxelKey v1{block.x * map::kBlockSize + map::kBlockMask + r, block.y * map::kBlockSize + map::kBlockMask + r,
                    block.z * map::kBlockSize + map::kBlockMask + r};
  const int x0 = std::max(floor_div(v0.x, l.stride) - l.origin.x, 0),
            x1 = std::min(floor_div(v1.x, l.stride) - l.origin.x, l.nx - 1);
  const int y0 = std::max(floor_div(v0.y, l.stride) - l.origin.y, 0),
            y1 = std::min(floor_div(v1.y, l.stride) - l.origin.y, l.ny - 1);
  const int z0 = std::max(floor_div(v0.z, l.stride) - l.origin.z, 0),
            z1 = std::min(floor_div(v1.z, l.stride) - l.origin.z, l.nz - 1);
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const size_t row = static_cast<size_t>(l.nx) * (static_cast<size_t>(y) + static_cast<size_t>(l.ny) * z);
      if (x0 <= x1) std::fill(l.cls.begin() + static_cast<long>(row) + x0, l.cls.begin() + static_cast<long>(row) + x1 + 1, kUnset);
    }
}

uint8_t GridSearch::cls(Lattice& l, int64_t i) {
  uint8_t& c = l.cls[static_cast<size_t>(i)];
  if (c != kUnset) return c;
  const Eigen::Vector3d p = point(l, l.coords(i));
  if (grid_->state(p) != VoxelState::kFree) return c = kBlocked;
  const double e = checker_.esdf(p, checker_.cached_cap());
  c = e >= collision_.passage_clearance ? kHigh : (e >= l.threshold ? kLow : kBlocked);
  return c;
}

uint8_t GridSearch::passable(Lattice& l, int64_t i, const Eigen::Vector3d& source, bool escape) {
  const uint8_t c = cls(l, i);
  if (c != kBlocked || !escape) return c;
  const Eigen::Vector3d p = point(l, l.coords(i));
  if ((p - source).norm() > collision_.root_escape_radius) return kBlocked;
  // The box check is dear and a cell is asked about by each of its neighbours: once per search.
  const auto it = escape_cache_.find(i);
  if (it != escape_cache_.end()) return it->second;
  const uint8_t e = grid_->state(p) == VoxelState::kFree && checker_.vehicle_free(p) ? kLow : kBlocked;
  escape_cache_.emplace(i, e);
  return e;
}

std::vector<int64_t> GridSearch::cells_near(const Lattice& l, const Eigen::Vector3d& p) const {
  std::vector<int64_t> out;
  const VoxelKey c = lattice_of(l, p);
  const int64_t i = l.index(c);
  if (i >= 0) out.push_back(i);
  for (const Step& s : steps()) {
    const int64_t j = l.index(c + s.d);
    if (j >= 0) out.push_back(j);
  }
  return out;
}

template <class Allowed, class Settle>
int64_t GridSearch::search(Lattice& l, const std::vector<std::pair<int64_t, double>>& seeds,
                           const Eigen::Vector3d& source, bool escape, int64_t goal_index,
                           const Eigen::Vector3d& goal, int64_t max_settled, Allowed&& allowed, Settle&& settle) {
  if (++l.now == 0) {  // the stamps wrapped: start them over
    std::fill(l.stamp.begin(), l.stamp.end(), 0);
    std::fill(l.closed.begin(), l.closed.end(), 0);
    l.now = 1;
  }
  escape_cache_.clear();
  const double cell = grid_->resolution() * l.stride;
  const bool astar = goal_index >= 0;
  using Item = std::pair<float, int64_t>;  // (g + h, index); ties go to the lower index
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  auto h = [&](int64_t i) { return astar ? static_cast<float>((point(l, l.coords(i)) - goal).norm()) : 0.0f; };
  for (const auto& [i, g0] : seeds) {
    const float g = static_cast<float>(g0);
    if (l.stamp[static_cast<size_t>(i)] == l.now && l.g[static_cast<size_t>(i)] <= g) continue;
    l.stamp[static_cast<size_t>(i)] = l.now;
    l.g[static_cast<size_t>(i)] = g;
    l.parent[static_cast<size_t>(i)] = -1;
    open.emplace(g + h(i), i);
  }
  int64_t settled = 0;
  while (!open.empty() && settled < max_settled) {
    const auto [f, i] = open.top();
    open.pop();
    const size_t si = static_cast<size_t>(i);
    if (l.closed[si] == l.now) continue;
    l.closed[si] = l.now;
    ++settled;
    if (settle(i)) break;
    const VoxelKey c = l.coords(i);
    const float gi = l.g[si];
    for (const Step& st : steps()) {
      const int64_t j = l.index(c + st.d);
      if (j < 0 || l.closed[static_cast<size_t>(j)] == l.now || !allowed(j)) continue;
      const bool is_goal = j == goal_index;
      const uint8_t pj = is_goal ? static_cast<uint8_t>(kLow) : passable(l, j, source, escape);
      if (pj == kBlocked) continue;
      bool cut = false;
      for (const VoxelKey& a : st.across) {
        const int64_t k = l.index(c + a);
        if (k < 0 || passable(l, k, source, escape) == kBlocked) {
          cut = true;
          break;
        }
      }
      if (cut) continue;
      const double w = pj == kHigh ? 1.0 : 1.0 + low_penalty_;
      const float g = gi + static_cast<float>(st.length * cell * w);
      const size_t sj = static_cast<size_t>(j);
      if (l.stamp[sj] == l.now && l.g[sj] <= g) continue;
      l.stamp[sj] = l.now;
      l.g[sj] = g;
      l.parent[sj] = static_cast<int32_t>(i);
      open.emplace(g + h(j), j);
    }
  }
  return settled;
}

GridSearch::Result GridSearch::distances(const Eigen::Vector3d& source, bool escape,
                                         const std::vector<Eigen::Vector3d>& targets, int64_t max_settled,
                                         bool keep_tree) {
  Result r;
  r.distance.assign(targets.size(), kInf);
  if (keep_tree) tree_valid_ = false;
  if (!grid_ || !source.allFinite()) return r;
  Lattice& l = coarse_;
  prepare(l);
  const int64_t s = l.nx > 0 ? l.index(lattice_of(l, source)) : -1;
  if (s < 0) return r;
  // The escape rule only where the vehicle needs it (the source's own cell is not passable).
  escape = escape && cls(l, s) == kBlocked;
  std::vector<std::pair<int64_t, double>> seeds;
  if (escape || cls(l, s) != kBlocked) {
    seeds.emplace_back(s, (point(l, l.coords(s)) - source).norm());
  } else {
    for (int64_t j : cells_near(l, source))
      if (cls(l, j) != kBlocked) seeds.emplace_back(j, (point(l, l.coords(j)) - source).norm());
  }
  // Each target is served by its cell and the cells around it.
  std::unordered_map<int64_t, std::vector<size_t>> serves;
  std::vector<std::vector<int64_t>> near(targets.size());
  for (size_t t = 0; t < targets.size(); ++t) {
    if (!targets[t].allFinite()) continue;
    near[t] = cells_near(l, targets[t]);
    for (int64_t j : near[t]) serves[j].push_back(t);
  }
  std::vector<bool> touched(targets.size(), false);
  size_t left = 0;
  for (size_t t = 0; t < targets.size(); ++t) left += near[t].empty() ? 0 : 1;
  r.settled = search(
      l, seeds, source, escape, -1, source, max_settled, [](int64_t) { return true; },
      [&](int64_t i) {
        const auto it = serves.find(i);
        if (it == serves.end()) return false;
        for (size_t t : it->second) {
          if (!touched[t]) {
            touched[t] = true;
            --left;
          }
        }
        return left == 0 && !keep_tree;
      });
  for (size_t t = 0; t < targets.size(); ++t) {
    for (int64_t j : near[t]) {
      if (l.closed[static_cast<size_t>(j)] != l.now) continue;
      r.distance[t] = std::min(r.distance[t], static_cast<double>(l.g[static_cast<size_t>(j)]) +
                                                  (targets[t] - point(l, l.coords(j))).norm());
    }
  }
  if (keep_tree) {
    tree_valid_ = true;
    tree_source_ = source;
    tree_origin_ = l.origin;
    tree_nx_ = l.nx;
    tree_ny_ = l.ny;
    tree_nz_ = l.nz;
    tree_g_.assign(l.g.size(), kInfF);
    tree_parent_ = l.parent;
    for (size_t i = 0; i < l.g.size(); ++i)
      if (l.closed[i] == l.now) tree_g_[i] = l.g[i];
  }
  return r;
}

std::vector<Eigen::Vector3d> GridSearch::tree_path(const Eigen::Vector3d& target) const {
  std::vector<Eigen::Vector3d> out;
  if (!tree_valid_ || !grid_ || !target.allFinite()) return out;
  Lattice t;  // the tree's geometry
  t.stride = coarse_.stride;
  t.origin = tree_origin_;
  t.nx = tree_nx_;
  t.ny = tree_ny_;
  t.nz = tree_nz_;
  int64_t best = -1;
  double best_d = kInf;
  for (int64_t j : cells_near(t, target)) {
    const double g = tree_g_[static_cast<size_t>(j)];
    if (!(g < kInf)) continue;
    const double d = g + (target - point(t, t.coords(j))).norm();
    if (d < best_d) best_d = d, best = j;
  }
  if (best < 0) return out;
  std::vector<Eigen::Vector3d> rev{target};
  for (int64_t i = best; i >= 0; i = tree_parent_[static_cast<size_t>(i)]) rev.push_back(point(t, t.coords(i)));
  rev.push_back(tree_source_);
  out.assign(rev.rbegin(), rev.rend());
  return out;
}

bool GridSearch::find_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::vector<Eigen::Vector3d>& guide,
                           int64_t max_expansions, std::vector<Eigen::Vector3d>& out, int64_t* expanded) {
  out.clear();
  if (expanded) *expanded = 0;
  if (!grid_ || !a.allFinite() || !b.allFinite()) return false;
  // A straight line first (FUEL's ViewNode::searchPath).
  if (checker_.root_edge_free(a, b)) {
    out = {a, b};
    return true;
  }
  Lattice& l = fine_;
  prepare(l);
  const int64_t s = l.nx > 0 ? l.index(lattice_of(l, a)) : -1;
  const int64_t goal = l.nx > 0 ? l.index(lattice_of(l, b)) : -1;
  if (s < 0 || goal < 0) return false;
  const bool escape = cls(l, s) == kBlocked;
  // The corridor: coarse cells within two of the guide's.
  std::unordered_set<uint64_t> corridor;
  const int cs = coarse_.stride;
  for (const Eigen::Vector3d& g : guide) {
    const VoxelKey c = lattice_of(coarse_, g);
    for (int dz = -2; dz <= 2; ++dz)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) corridor.insert(pack(VoxelKey{c.x + dx, c.y + dy, c.z + dz}));
  }
  auto allowed = [&](int64_t j) {
    if (corridor.empty()) return true;
    const VoxelKey v = l.coords(j);
    return corridor.count(pack(VoxelKey{floor_div(v.x, cs), floor_div(v.y, cs), floor_div(v.z, cs)})) != 0;
  };
  bool reached = false;
  const int64_t n = search(l, {{s, 0.0}}, a, escape, goal, b, max_expansions, allowed, [&](int64_t i) {
    reached = i == goal;
    return reached;
  });
  if (expanded) *expanded = n;
  if (!reached) return false;
  std::vector<Eigen::Vector3d> rev{b};
  for (int64_t i = l.parent[static_cast<size_t>(goal)]; i >= 0 && i != s; i = l.parent[static_cast<size_t>(i)])
    rev.push_back(point(l, l.coords(i)));
  rev.push_back(a);
  const std::vector<Eigen::Vector3d> raw(rev.rbegin(), rev.rend());
  return shorten(raw, out);
}

bool GridSearch::shorten(const std::vector<Eigen::Vector3d>& path, std::vector<Eigen::Vector3d>& out) const {
  out.clear();
  if (path.empty()) return false;
  out.push_back(path.front());
  const int n = static_cast<int>(path.size());
  auto ok = [&](int i, int j) {
    return i == 0 ? checker_.root_edge_free(path[0], path[static_cast<size_t>(j)])
                  : checker_.edge_free(path[static_cast<size_t>(i)], path[static_cast<size_t>(j)]);
  };
  int i = 0;
  while (i < n - 1) {
    // The farthest point the anchor can be joined to: doubling steps to the first failure, then
    // halving between the last success and it (any success found is a valid segment).
    if (!ok(i, i + 1)) return false;
    int good = i + 1, bad = -1;
    for (int step = 2; i + step < n; step *= 2) {
      if (ok(i, i + step)) {
        good = i + step;
      } else {
        bad = i + step;
        break;
      }
    }
    if (bad < 0 && good != n - 1 && ok(i, n - 1)) good = n - 1;
    if (bad < 0 && good != n - 1) bad = n - 1;
    while (bad > good + 1) {
      const int mid = (good + bad) / 2;
      (ok(i, mid) ? good : bad) = mid;
    }
    out.push_back(path[static_cast<size_t>(good)]);
    i = good;
  }
  return true;
}

}  // namespace semx::planner
