#include "semx/planner/grid_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>
#include <utility>

#include "semx/core/queue_key.hpp"
#include "semx/core/radix_heap.hpp"

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr double kInf = std::numeric_limits<double>::infinity();
// A step into a cell passable only by the escape rule costs this many times its length.
constexpr double kEscapePenalty = 20.0;
// Changes invalidate passability by cubes of 2^kDirtyBits voxels.
constexpr int kDirtyBits = 2;
// m: the body box grown by this keeps off every voxel along a segment, checked this often.
constexpr double kBodyMargin = 0.02;
constexpr double kBodyStep = 0.05;
// A search without a guide first tries to prove the goal enclosed, settling at most this many
// voxels (the pocket of semantic-fuel's failed search in g224 had 1424): a proof that does not run
// dry is work thrown away, before every such search that finds its path.
constexpr int64_t kPocketVoxels = 4000;

int32_t floor_div(int32_t v, int32_t s) { return v >= 0 ? v / s : -((-v + s - 1) / s); }

// The 26 steps, each with its length in cells and the cells it cuts across (the steps along a
// proper subset of its axes), so a diagonal step cannot slip between two blocked cells. Cells of
// the 3x3x3 block around a cell are numbered (dx + 1) + 3 (dy + 1) + 9 (dz + 1); 13 is the cell.
struct Step {
  VoxelKey d;
  int k = 0;
  double length = 0.0;
  int across[6] = {0, 0, 0, 0, 0, 0};
  int n_across = 0;
};

int block_index(const VoxelKey& d) { return (d.x + 1) + 3 * (d.y + 1) + 9 * (d.z + 1); }

const std::vector<Step>& steps() {
  static const std::vector<Step> s = [] {
    std::vector<Step> out;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          Step st;
          st.d = {dx, dy, dz};
          st.k = block_index(st.d);
          st.length = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          for (int mask = 1; mask < 7; ++mask) {
            const VoxelKey sub{(mask & 1) ? dx : 0, (mask & 2) ? dy : 0, (mask & 4) ? dz : 0};
            if (sub == st.d || sub == VoxelKey{0, 0, 0}) continue;
            const int k = block_index(sub);
            if (std::find(st.across, st.across + st.n_across, k) == st.across + st.n_across) st.across[st.n_across++] = k;
          }
          out.push_back(st);
        }
    return out;
  }();
  return s;
}

// A* takes (cost, index) as one word (core/queue_key.hpp): one compare in the heap's sifts where
// the pair took two. Lattice indices fit 32 bits as the parents (int32_t) do.
uint64_t queue_item(float cost, int64_t index) { return core::queue_key(cost, static_cast<uint32_t>(index)); }
int64_t queue_index(uint64_t item) { return core::queue_key_index(item); }
using Queue = std::priority_queue<uint64_t, std::vector<uint64_t>, std::greater<uint64_t>>;

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
  // By cubes of kDirtyBits^3 voxels, not map blocks: a change invalidates what lies within the
  // ESDF's reach of its cube, and a 16^3 block grown by that reach is four times the volume.
  // A cell's class reads only whether voxels are free (every other state is an obstacle to it):
  // unknown -> occupied, most of what a camera adds at the edge of the known space, changes no
  // cell. A voxel that becomes free can only raise the ESDF around it, so kHigh cells, the top
  // class, stay: in FUEL's 600 m² run most cells near a growing frontier were kHigh and were
  // searched again after every map update.
  for (const map::VoxelChange& c : changes) {
    const bool free_after = c.state == VoxelState::kFree;
    if (c.previous && (*c.previous == VoxelState::kFree) == free_after) continue;
    const bool lowers = !c.previous || !free_after;
    const VoxelKey b{c.key.x >> kDirtyBits, c.key.y >> kDirtyBits, c.key.z >> kDirtyBits};
    dirty_coarse_[b] |= lowers;
    dirty_fine_[b] |= lowers;
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
  std::map<VoxelKey, bool>& dirty = &l == &coarse_ ? dirty_coarse_ : dirty_fine_;
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
    // Grow with room to spare, keeping what is cached: at least 2 m horizontally and 0.8 m
    // vertically, and horizontally half the known box's extent. Every growth writes the whole
    // lattice (17 bytes a voxel); with a fixed 2 m the fine one grew every few seconds of a 600 m²
    // exploration, 20-38 ms each time, the most of FUEL's cycles above 20 ms. Growing with the box
    // makes that a few times a run. Results do not depend on the box: ties in the searches go to
    // the lower index, which orders cells by (z, y, x) wherever the box starts.
    const int mxy = std::max(2, static_cast<int>(std::ceil(2.0 / (res * l.stride))));
    const int mz = std::max(1, static_cast<int>(std::ceil(0.8 / (res * l.stride))));
    const int mx = std::max(mxy, (hi.x - lo.x) / 2), my = std::max(mxy, (hi.y - lo.y) / 2);
    VoxelKey nlo{lo.x - mx, lo.y - my, lo.z - mz}, nhi{hi.x + mx, hi.y + my, hi.z + mz};
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
    static_assert(kUnset == 0, "a new lattice's cells start unset");
    n.cls = core::ZeroArray<uint8_t>(cells);
    // The old box lies inside the new one: copy it row by row.
    const size_t ox = static_cast<size_t>(l.origin.x - n.origin.x);
    for (int z = 0; z < l.nz; ++z)
      for (int y = 0; y < l.ny; ++y) {
        const size_t src = static_cast<size_t>(l.nx) * (static_cast<size_t>(y) + static_cast<size_t>(l.ny) * z);
        const size_t dst = static_cast<size_t>(n.nx) * (static_cast<size_t>(y + l.origin.y - n.origin.y) +
                                                        static_cast<size_t>(n.ny) * (z + l.origin.z - n.origin.z)) +
                           ox;
        std::copy(l.cls.begin() + src, l.cls.begin() + src + static_cast<size_t>(l.nx), n.cls.begin() + dst);
      }
    n.g = core::ZeroArray<float>(cells);
    n.parent = core::ZeroArray<int32_t>(cells);
    n.stamp = core::ZeroArray<uint32_t>(cells);
    n.closed = core::ZeroArray<uint32_t>(cells);
    const size_t columns = static_cast<size_t>(n.nx) * static_cast<size_t>(n.ny);
    n.col_set = core::ZeroArray<uint8_t>(columns);
    n.col_pass = core::ZeroArray<uint64_t>(columns);
    n.col_high = core::ZeroArray<uint64_t>(columns);
    n.col_g = core::ZeroArray<float>(columns);
    n.col_parent = core::ZeroArray<int32_t>(columns);
    n.col_stamp = core::ZeroArray<uint32_t>(columns);
    n.col_closed = core::ZeroArray<uint32_t>(columns);
    l = std::move(n);
    if (&l == &coarse_) tree_valid_ = false;
  }
  for (const auto& [b, lowers] : dirty) invalidate(l, b, lowers);
  dirty.clear();
}

void GridSearch::invalidate(Lattice& l, const VoxelKey& block, bool lowers) {  // block: a 4^3 cube (kDirtyBits)
  // A voxel changes the ESDF of centres within the checker's cap, and a cell reads the 8 centres
  // around its point: everything within cap + a cell of the block's voxels.
  const double res = grid_->resolution();
  // A cell's class compares its ESDF with passage_clearance at most; a voxel farther than that
  // plus the interpolation's reach (a voxel) and the cell's own extent cannot change it.
  const int r = static_cast<int>(std::ceil((collision_.passage_clearance + (l.stride + 1) * res) / res));
  constexpr int kSize = 1 << kDirtyBits;
  const VoxelKey v0{block.x * kSize - r, block.y * kSize - r, block.z * kSize - r};
  const VoxelKey v1{block.x * kSize + kSize - 1 + r, block.y * kSize + kSize - 1 + r, block.z * kSize + kSize - 1 + r};
  const int x0 = std::max(floor_div(v0.x, l.stride) - l.origin.x, 0),
            x1 = std::min(floor_div(v1.x, l.stride) - l.origin.x, l.nx - 1);
  const int y0 = std::max(floor_div(v0.y, l.stride) - l.origin.y, 0),
            y1 = std::min(floor_div(v1.y, l.stride) - l.origin.y, l.ny - 1);
  const int z0 = std::max(floor_div(v0.z, l.stride) - l.origin.z, 0),
            z1 = std::min(floor_div(v1.z, l.stride) - l.origin.z, l.nz - 1);
  for (int y = y0; y <= y1 && !l.col_set.empty(); ++y)
    for (int x = x0; x <= x1; ++x) l.col_set[static_cast<size_t>(x) + static_cast<size_t>(l.nx) * y] = 0;
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const size_t row = static_cast<size_t>(l.nx) * (static_cast<size_t>(y) + static_cast<size_t>(l.ny) * z);
      if (x0 > x1) continue;
      uint8_t* c = &l.cls[row];
      if (lowers) {
        std::fill(c + x0, c + x1 + 1, kUnset);
      } else {
        for (int x = x0; x <= x1; ++x)
          if (c[x] != kHigh) c[x] = kUnset;
      }
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
  // Unknown voxels pass too, as on root_edge_free's centre line near the root: the mapper leaves
  // the camera's first half metre unknown, so a vehicle that has not moved yet sits in unknown
  // space (the process set's env2 run never left its start before this).
  const uint8_t e = grid_->state(p) != VoxelState::kOccupied && checker_.vehicle_free(p) ? kEscape : kBlocked;
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
                           const Eigen::Vector3d& source, bool escape, int64_t goal_index, int64_t open_index,
                           const Eigen::Vector3d& goal, int64_t max_settled, Allowed&& allowed,
                           Settle&& settle) {
  if (++l.now == 0) {  // the stamps wrapped: start them over
    std::fill(l.stamp.begin(), l.stamp.end(), 0);
    std::fill(l.closed.begin(), l.closed.end(), 0);
    l.now = 1;
  }
  escape_cache_.clear();
  const double cell = grid_->resolution() * l.stride;
  const bool astar = goal_index >= 0;
  int64_t offset[27];
  for (const Step& st : steps()) offset[st.k] = st.d.x + static_cast<int64_t>(l.nx) * (st.d.y + static_cast<int64_t>(l.ny) * st.d.z);
  Queue open;  // g + h and the index; ties go to the lower index
  auto h = [&](const VoxelKey& v) { return astar ? static_cast<float>((point(l, v) - goal).norm()) : 0.0f; };
  for (const auto& [i, g0] : seeds) {
    const float g = static_cast<float>(g0);
    if (l.stamp[static_cast<size_t>(i)] == l.now && l.g[static_cast<size_t>(i)] <= g) continue;
    l.stamp[static_cast<size_t>(i)] = l.now;
    l.g[static_cast<size_t>(i)] = g;
    l.parent[static_cast<size_t>(i)] = -1;
    open.push(queue_item(g + h(l.coords(i)), i));
  }
  int64_t settled = 0;
  while (!open.empty() && settled < max_settled) {
    const int64_t i = queue_index(open.top());
    open.pop();
    const size_t si = static_cast<size_t>(i);
    if (l.closed[si] == l.now) continue;
    l.closed[si] = l.now;
    ++settled;
    if (settle(i)) break;
    const VoxelKey c = l.coords(i);
    const float gi = l.g[si];
    // Each cell of the block around c is asked once (a step and the cells it cuts across share
    // them); inside the box the neighbours' indices are fixed offsets.
    const bool inside = c.x > l.origin.x && c.y > l.origin.y && c.z > l.origin.z && c.x < l.origin.x + l.nx - 1 &&
                        c.y < l.origin.y + l.ny - 1 && c.z < l.origin.z + l.nz - 1;
    int64_t nb_index[27];
    uint8_t nb[27];
    for (const Step& st : steps()) {
      const int64_t j = inside ? i + offset[st.k] : l.index(c + st.d);
      nb_index[st.k] = j;
      nb[st.k] = j < 0 ? static_cast<uint8_t>(kBlocked)
                       : (j == goal_index || j == open_index ? static_cast<uint8_t>(kLow)
                                                             : passable(l, j, source, escape));
    }
    for (const Step& st : steps()) {
      const int64_t j = nb_index[st.k];
      const uint8_t pj = nb[st.k];
      if (pj == kBlocked || l.closed[static_cast<size_t>(j)] == l.now) continue;
      const VoxelKey cj = c + st.d;
      if (!allowed(cj)) continue;
      bool cut = false;
      for (int a = 0; a < st.n_across && !cut; ++a) cut = nb[st.across[a]] == kBlocked;
      if (cut) continue;
      // Cells passable only by the escape rule cost much more: the path leaves them at once.
      const double w = pj == kHigh ? 1.0 : (pj == kEscape ? kEscapePenalty : 1.0 + low_penalty_);
      const float g = gi + static_cast<float>(st.length * cell * w);
      const size_t sj = static_cast<size_t>(j);
      if (l.stamp[sj] == l.now && l.g[sj] <= g) continue;
      l.stamp[sj] = l.now;
      l.g[sj] = g;
      l.parent[sj] = static_cast<int32_t>(i);
      open.push(queue_item(g + h(cj), j));
    }
  }
  return settled;
}

void GridSearch::column(int64_t col, uint64_t& pass, uint64_t& high) {
  Lattice& l = coarse_;
  if (l.col_set[static_cast<size_t>(col)]) {
    pass = l.col_pass[static_cast<size_t>(col)];
    high = l.col_high[static_cast<size_t>(col)];
    return;
  }
  pass = high = 0;
  const int64_t plane = static_cast<int64_t>(l.nx) * l.ny;
  for (int z = 0; z < std::min(l.nz, 64); ++z) {
    const uint8_t c = cls(l, col + plane * z);
    if (c != kBlocked) pass |= uint64_t{1} << z;
    if (c == kHigh) high |= uint64_t{1} << z;
  }
  l.col_set[static_cast<size_t>(col)] = 1;
  l.col_pass[static_cast<size_t>(col)] = pass;
  l.col_high[static_cast<size_t>(col)] = high;
}

GridSearch::Result GridSearch::distances(const Eigen::Vector3d& source, bool escape,
                                         const std::vector<Eigen::Vector3d>& targets, int64_t max_settled,
                                         bool keep_tree) {
  Result r;
  r.distance.assign(targets.size(), kInf);
  if (keep_tree) tree_valid_ = false;
  if (!grid_ || !source.allFinite() || targets.empty()) return r;
  Lattice& l = coarse_;
  prepare(l);
  if (l.nx <= 0) return r;
  const VoxelKey sc = lattice_of(l, source);
  const int64_t s3 = l.index(sc);
  if (s3 < 0) return r;
  const int64_t plane = static_cast<int64_t>(l.nx) * l.ny;
  const int64_t s = s3 % plane;
  // The escape rule only where the vehicle needs it (the source's own cell is not passable).
  escape = escape && cls(l, s3) == kBlocked;
  const double cell = grid_->resolution() * l.stride;
  auto centre = [&](int64_t col) -> Eigen::Vector2d {
    return Eigen::Vector2d((l.origin.x + col % l.nx) * l.stride + 0.5 * l.stride,
                           (l.origin.y + col / l.nx) * l.stride + 0.5 * l.stride) *
           grid_->resolution();
  };
  // A column's heights, with those of the escape zone around the source.
  std::unordered_map<int64_t, std::pair<uint64_t, uint64_t>> escaped;
  auto heights = [&](int64_t col, uint64_t& pass, uint64_t& high) {
    column(col, pass, high);
    if (!escape || (centre(col) - source.head<2>()).norm() > collision_.root_escape_radius + cell) return;
    const auto it = escaped.find(col);
    if (it != escaped.end()) {
      pass = it->second.first;
      high = it->second.second;
      return;
    }
    for (int z = 0; z < std::min(l.nz, 64); ++z)
      if (!(pass >> z & 1u) && passable(l, col + plane * z, source, true) != kBlocked) pass |= uint64_t{1} << z;
    escaped.emplace(col, std::make_pair(pass, high));
  };
  escape_cache_.clear();
  if (++l.now == 0) {
    std::fill(l.col_stamp.begin(), l.col_stamp.end(), 0);
    std::fill(l.col_closed.begin(), l.col_closed.end(), 0);
    l.now = 1;
  }
  // Every step costs > 0, so no entry pushed is below the one popped: a radix heap pops in the
  // binary heap's order (ties by column) with each entry moved once or twice instead of ~log n.
  core::RadixHeap& open = column_queue_;
  open.clear();
  auto seed = [&](int64_t col) {
    const float g = static_cast<float>((centre(col) - source.head<2>()).norm());
    const size_t i = static_cast<size_t>(col);
    if (l.col_stamp[i] == l.now && l.col_g[i] <= g) return;
    l.col_stamp[i] = l.now;
    l.col_g[i] = g;
    l.col_parent[i] = -1;
    open.push(queue_item(g, col));
  };
  uint64_t sp = 0, sh = 0;
  heights(s, sp, sh);
  const int sx = static_cast<int>(s % l.nx), sy = static_cast<int>(s / l.nx);
  if (sp != 0) {
    seed(s);
  } else {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (sx + dx < 0 || sy + dy < 0 || sx + dx >= l.nx || sy + dy >= l.ny) continue;
        const int64_t c = s + dx + static_cast<int64_t>(l.nx) * dy;
        uint64_t p = 0, h = 0;
        heights(c, p, h);
        if (p != 0) seed(c);
      }
  }
  // Each target is served by its column and the eight around it.
  // Per column the first of the targets it serves, chained through serve_next (-1 ends): read for
  // every column settled, so an array, not a hash map.
  std::vector<int32_t> serve_head(static_cast<size_t>(plane), -1);
  std::vector<std::pair<int32_t, int32_t>> serve_next;  // (target, next)
  std::vector<std::vector<int64_t>> near(targets.size());
  for (size_t t = 0; t < targets.size(); ++t) {
    if (!targets[t].allFinite()) continue;
    const int64_t c3 = l.index(lattice_of(l, targets[t]));
    if (c3 < 0) continue;
    const int64_t c = c3 % plane;
    const int cx = static_cast<int>(c % l.nx), cy = static_cast<int>(c / l.nx);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (cx + dx < 0 || cy + dy < 0 || cx + dx >= l.nx || cy + dy >= l.ny) continue;
        const int64_t j = c + dx + static_cast<int64_t>(l.nx) * dy;
        near[t].push_back(j);
        serve_next.emplace_back(static_cast<int32_t>(t), serve_head[static_cast<size_t>(j)]);
        serve_head[static_cast<size_t>(j)] = static_cast<int32_t>(serve_next.size() - 1);
      }
  }
  std::vector<bool> touched(targets.size(), false);
  size_t left = 0;
  for (size_t t = 0; t < targets.size(); ++t) left += near[t].empty() ? 0 : 1;
  static const int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1}, kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  while (!open.empty() && r.settled < max_settled && left > 0) {
    const int64_t c = queue_index(open.pop());
    const size_t ci = static_cast<size_t>(c);
    if (l.col_closed[ci] == l.now) continue;
    l.col_closed[ci] = l.now;
    ++r.settled;
    for (int32_t e = serve_head[ci]; e >= 0; e = serve_next[static_cast<size_t>(e)].second) {
      const size_t t = static_cast<size_t>(serve_next[static_cast<size_t>(e)].first);
      if (!touched[t]) touched[t] = true, --left;
    }
    uint64_t pc = 0, hc = 0;
    heights(c, pc, hc);
    const int cx = static_cast<int>(c % l.nx), cy = static_cast<int>(c / l.nx);
    for (int k = 0; k < 8; ++k) {
      const int nx = cx + kDx[k], ny = cy + kDy[k];
      if (nx < 0 || ny < 0 || nx >= l.nx || ny >= l.ny) continue;
      const int64_t n = nx + static_cast<int64_t>(l.nx) * ny;
      if (l.col_closed[static_cast<size_t>(n)] == l.now) continue;
      uint64_t pn = 0, hn = 0;
      heights(n, pn, hn);
      // A step needs a height both columns are passable at (and, diagonally, the two columns it
      // cuts between too).
      uint64_t common = pc & pn, open_high = hc & hn;
      if (k >= 4) {
        uint64_t pa = 0, ha = 0, pb = 0, hb = 0;
        heights(cx + kDx[k] + static_cast<int64_t>(l.nx) * cy, pa, ha);
        heights(cx + static_cast<int64_t>(l.nx) * (cy + kDy[k]), pb, hb);
        common &= pa & pb;
        open_high &= ha & hb;
      }
      if (common == 0) continue;
      const double w = open_high != 0 ? 1.0 : 1.0 + low_penalty_;
      const float g = l.col_g[ci] + static_cast<float>((k >= 4 ? std::sqrt(2.0) : 1.0) * cell * w);
      const size_t ni = static_cast<size_t>(n);
      if (l.col_stamp[ni] == l.now && l.col_g[ni] <= g) continue;
      l.col_stamp[ni] = l.now;
      l.col_g[ni] = g;
      l.col_parent[ni] = static_cast<int32_t>(c);
      open.push(queue_item(g, n));
    }
  }
  // The columns ignore height: the climb between source and target is added to the horizontal
  // path (in quadrature, as if spread along it).
  for (size_t t = 0; t < targets.size(); ++t) {
    double best = kInf;
    for (int64_t j : near[t]) {
      if (l.col_closed[static_cast<size_t>(j)] != l.now) continue;
      best = std::min(best, static_cast<double>(l.col_g[static_cast<size_t>(j)]) +
                                (targets[t].head<2>() - centre(j)).norm());
    }
    if (best < kInf) r.distance[t] = std::hypot(best, targets[t].z() - source.z());
  }
  if (keep_tree) {
    tree_valid_ = true;
    tree_source_ = source;
    tree_origin_ = l.origin;
    tree_nx_ = l.nx;
    tree_ny_ = l.ny;
    tree_g_.assign(l.col_g.size(), kInfF);
    tree_parent_.assign(l.col_parent.begin(), l.col_parent.end());
    for (size_t i = 0; i < l.col_g.size(); ++i)
      if (l.col_closed[i] == l.now) tree_g_[i] = l.col_g[i];
  }
  return r;
}

std::vector<Eigen::Vector3d> GridSearch::tree_path(const Eigen::Vector3d& target) const {
  std::vector<Eigen::Vector3d> out;
  if (!tree_valid_ || !grid_ || !target.allFinite()) return out;
  const double res = grid_->resolution();
  const int st = coarse_.stride;
  const VoxelKey v = grid_->keys().key(target);
  const int cx = floor_div(v.x, st) - tree_origin_.x, cy = floor_div(v.y, st) - tree_origin_.y;
  auto centre = [&](int64_t col) -> Eigen::Vector2d {
    return Eigen::Vector2d((tree_origin_.x + col % tree_nx_) * st + 0.5 * st,
                           (tree_origin_.y + col / tree_nx_) * st + 0.5 * st) *
           res;
  };
  int64_t best = -1;
  double best_d = kInf;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      if (cx + dx < 0 || cy + dy < 0 || cx + dx >= tree_nx_ || cy + dy >= tree_ny_) continue;
      const int64_t j = cx + dx + static_cast<int64_t>(tree_nx_) * (cy + dy);
      const double g = tree_g_[static_cast<size_t>(j)];
      if (!(g < kInf)) continue;
      const double d = g + (target.head<2>() - centre(j)).norm();
      if (d < best_d) best_d = d, best = j;
    }
  if (best < 0) return out;
  std::vector<Eigen::Vector2d> rev;
  for (int64_t i = best; i >= 0; i = tree_parent_[static_cast<size_t>(i)]) rev.push_back(centre(i));
  // Heights from the source's to the target's along the way (the corridor only uses x and y).
  out.push_back(tree_source_);
  const double n = static_cast<double>(rev.size() + 1);
  for (size_t k = 0; k < rev.size(); ++k) {
    const double t = static_cast<double>(k + 1) / n;
    const Eigen::Vector2d& c = rev[rev.size() - 1 - k];
    out.emplace_back(c.x(), c.y(), tree_source_.z() + t * (target.z() - tree_source_.z()));
  }
  out.push_back(target);
  return out;
}

bool GridSearch::find_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::vector<Eigen::Vector3d>& guide,
                           int64_t max_expansions, std::vector<Eigen::Vector3d>& out, int64_t* expanded) {
  bool pocket = false;
  if (find_path(a, b, guide, max_expansions, out, expanded, false, &pocket)) return true;
  if (!pocket) return false;
  // A start that has the bare body's clearance but no way off it under the usual rules: every
  // segment from it dips below the doorway clearance, or the cells around it that have the
  // clearance are walled off by cells without it. The vehicle stops in such places braking, or
  // gets there on a straight segment. Every view was then out of reach, and semantic-fuel declared
  // DONE at 67.6 % (env2's process set, seed 3, at 28 s: braked 0.343 m from the obstacles
  // between two pieces of furniture). Leaving is what the escape rule near the vehicle is for.
  int64_t more = 0;
  const bool found = find_path(a, b, guide, max_expansions, out, &more, true, nullptr);
  if (expanded) *expanded += more;
  return found;
}

bool GridSearch::find_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const std::vector<Eigen::Vector3d>& guide, int64_t max_expansions,
                           std::vector<Eigen::Vector3d>& out, int64_t* expanded, bool force_escape,
                           bool* pocket) {
  out.clear();
  if (expanded) *expanded = 0;
  if (!grid_ || !a.allFinite() || !b.allFinite()) return false;
  Lattice& l = fine_;
  prepare(l);
  const int64_t s = l.nx > 0 ? l.index(lattice_of(l, a)) : -1;
  const int64_t goal = l.nx > 0 ? l.index(lattice_of(l, b)) : -1;
  if (s < 0 || goal < 0) return false;
  // The vehicle itself may lack the clearance its voxel's centre has: held by the controller 0.337 m
  // from a wall (sensor noise, env3), every path from its voxel's centre failed the first segment's
  // check, the vehicle stayed there for 350 s and its viewpoints were skipped one by one.
  const bool escape = force_escape || cls(l, s) == kBlocked || !checker_.passage_free(a);
  // A straight line first (FUEL's ViewNode::searchPath), when the start has the clearance (else
  // the escape rule would let the whole first metre pass unknown voxels).
  if (!escape && checker_.edge_free(a, b) && body_clear(a, b)) {
    out = {a, b};
    return true;
  }
  // The corridor: coarse columns within two of the guide's, at any height. A dense mask over the
  // guide's box, as it is asked about for every neighbour of every voxel settled.
  const int cs = coarse_.stride;
  int cx0 = std::numeric_limits<int>::max(), cy0 = cx0, cx1 = std::numeric_limits<int>::min(), cy1 = cx1;
  std::vector<VoxelKey> guide_cells;
  guide_cells.reserve(guide.size());
  for (const Eigen::Vector3d& g : guide) {
    const VoxelKey c = lattice_of(coarse_, g);
    guide_cells.push_back(c);
    cx0 = std::min(cx0, c.x - 2), cy0 = std::min(cy0, c.y - 2);
    cx1 = std::max(cx1, c.x + 2), cy1 = std::max(cy1, c.y + 2);
  }
  const int cw = guide.empty() ? 0 : cx1 - cx0 + 1, ch = guide.empty() ? 0 : cy1 - cy0 + 1;
  std::vector<uint8_t> corridor(static_cast<size_t>(cw) * static_cast<size_t>(ch), 0);
  for (const VoxelKey& c : guide_cells)
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx)
        corridor[static_cast<size_t>(c.x + dx - cx0) +
                 static_cast<size_t>(cw) * static_cast<size_t>(c.y + dy - cy0)] = 1;
  auto allowed = [&](const VoxelKey& v) {
    if (guide.empty()) return true;
    const int x = floor_div(v.x, cs) - cx0, y = floor_div(v.y, cs) - cy0;
    return x >= 0 && y >= 0 && x < cw && y < ch &&
           corridor[static_cast<size_t>(x) + static_cast<size_t>(cw) * static_cast<size_t>(y)] != 0;
  };
  if (guide.empty() && s != goal) {
    // A view that the coarse lattice's lenient cells reach through a gap A* cannot pass made the
    // search without a guide settle its whole budget before failing: 100 000 voxels, ~70 ms, the
    // largest of semantic-fuel's cycles in the 600 m² world. When the view lies in a pocket, a
    // search from it runs dry first and proves that no path exists. It counts both ends as
    // passable, so it reaches every cell a path from the start could pass: the answer is the
    // search's own, found sooner.
    bool met = false;
    const int64_t budget = std::min(max_expansions, kPocketVoxels);
    const int64_t m = search(
        l, {{goal, 0.0}}, a, escape, s, goal, a, budget, [](const VoxelKey&) { return true; },
        [&](int64_t i) {
          met = i == s;
          return met;
        });
    if (!met && m < budget) {
      if (expanded) *expanded = m;
      return false;
    }
  }
  bool reached = false;
  const int64_t n = search(l, {{s, 0.0}}, a, escape, goal, -1, b, max_expansions, allowed, [&](int64_t i) {
    reached = i == goal;
    return reached;
  });
  if (expanded) *expanded = n;
  if (!reached) {
    // Ran dry from a start near obstacles: a pocket (the caller may try the escape rule).
    if (pocket) *pocket = !escape && n < std::min(max_expansions, kPocketVoxels) && cls(l, s) != kHigh;
    return false;
  }
  std::vector<Eigen::Vector3d> rev{b};
  std::vector<bool> rev_strict{true};
  for (int64_t i = l.parent[static_cast<size_t>(goal)]; i >= 0 && i != s; i = l.parent[static_cast<size_t>(i)]) {
    rev.push_back(point(l, l.coords(i)));
    rev_strict.push_back(cls(l, i) != kBlocked);
  }
  rev.push_back(a);
  const std::vector<Eigen::Vector3d> raw(rev.rbegin(), rev.rend());
  // From a start without the clearance, the first segment only leaves for the first point that
  // has it: a shortcut under the escape rule reaches past unknown voxels (a wall's corner not yet
  // seen: env2, seed 1, 8 steps in collision when each replan from such a start escaped again).
  size_t first = 0;
  if (escape) {
    first = 1;
    while (first + 1 < raw.size() && !rev_strict[raw.size() - 1 - first]) ++first;
  }
  if (shorten(raw, out, first)) return true;
  // A start with the bare body's clearance (passage_free) but not a node's may have no segment
  // off it that keeps edge_free's: the lattice path exists and its first hop fails.
  if (pocket) *pocket = !escape && !checker_.node_free(a);
  return false;
}

bool GridSearch::body_clear(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  // edge_free lets the bare body box touch a voxel's face where a doorway's clearance is allowed:
  // rounding a door leaf's end diagonally at an ESDF of 0.37 m, the box's corner met the leaf's
  // corner voxel (env3, seed 1, counted as a collision by the closed box of the closed loop).
  // Occupied voxels only: unknown ones keep edge_free's clearance already, and the grown box
  // against them refused every path from the process set's start, among unknown voxels the
  // camera has not seen.
  const Eigen::Vector3d half = 0.5 * collision_.vehicle_size + Eigen::Vector3d::Constant(kBodyMargin);
  const double length = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(length / kBodyStep)));
  for (int k = 0; k <= n; ++k)
    if (!checker_.box_free(a + (static_cast<double>(k) / n) * (b - a), half, false)) return false;
  return true;
}

bool GridSearch::shorten(const std::vector<Eigen::Vector3d>& path, std::vector<Eigen::Vector3d>& out,
                         size_t first) const {
  out.clear();
  if (path.empty()) return false;
  out.push_back(path.front());
  const int n = static_cast<int>(path.size());
  // The escape rule only for the hop off a start without the clearance (first > 0): from a start
  // with it, root_edge_free would still pass unknown voxels within its radius whenever the start
  // is not node_free, which a doorway never is (env3, seed 1: a wall's end not yet mapped, cut at
  // 0.33 m from a start 0.37 m off it).
  auto ok = [&](int i, int j) {
    const Eigen::Vector3d& p = path[static_cast<size_t>(i)];
    const Eigen::Vector3d& q = path[static_cast<size_t>(j)];
    return i == 0 && first > 0 ? checker_.root_edge_free(p, q) : checker_.edge_free(p, q) && body_clear(p, q);
  };
  int i = 0;
  if (first > 0 && static_cast<int>(first) < n) {
    for (size_t k = 1; k <= first; ++k)
      if (!checker_.root_edge_free(path[0], path[k])) return false;
    out.push_back(path[first]);
    i = static_cast<int>(first);
  }
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
