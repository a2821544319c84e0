#include "semx/planner/collision_checker.hpp"

#include <algorithm>
#include <cmath>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <limits>
#include <vector>

#include "semx/map/esdf_distance.hpp"
#include "semx/map/raycast.hpp"

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

CollisionChecker::CollisionChecker(const CollisionConfig& config)
    : config_(config),
      body_half_(0.5 * config.vehicle_size + Eigen::Vector3d::Constant(config.margin)),
      vehicle_half_(0.5 * config.vehicle_size),
      reach_(body_half_.cwiseMax(
          Eigen::Vector3d::Constant(std::max(config.clearance, config.passage_clearance)))),
      // Every cap the checks ask for: a clearance plus the slope allowance of half a coarse step.
      cache_cap_(std::max({config.clearance, config.passage_clearance, config.door_clearance,
                           kDoorUnknownClearance}) +
                 0.15) {}

namespace {

// The fills read the states' bits: kFree is 1, kOccupied 2.
static_assert(static_cast<uint8_t>(VoxelState::kUnknown) == 0 &&
              static_cast<uint8_t>(VoxelState::kFree) == 1 &&
              static_cast<uint8_t>(VoxelState::kOccupied) == 2 && sizeof(VoxelState) == 1);

static_assert(map::kBlockSize == 16, "a block row is one 16-byte load");

// The obstacles among a block row's 16 states as bits: every state but kFree when
// unknown_is_obstacle, else kOccupied only.
inline uint32_t obstacle_bits(const VoxelState* row, bool unknown_is_obstacle) {
#ifdef __SSE2__
  const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
  if (unknown_is_obstacle)
    return ~static_cast<uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_set1_epi8(1)))) & 0xffffu;
  return static_cast<uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_set1_epi8(2))));
#else
  uint32_t bits = 0;
  for (int i = 0; i < 16; ++i) {
    const VoxelState s = row[i];
    if (unknown_is_obstacle ? s != VoxelState::kFree : s == VoxelState::kOccupied) bits |= uint32_t{1} << i;
  }
  return bits;
#endif
}

// out[i] = min(out[i], g[i] + q) over a chunk row of eight squared distances (none overflows:
// they stay below 3 reach^2). GCC left this loop scalar, and it was 40 % of a fill's instructions.
static_assert(CollisionChecker::kChunkSize == 8, "a chunk row is one 16-byte load of int16");
inline void min_plus_row(int16_t* out, const int16_t* g, int16_t q) {
#ifdef __SSE2__
  __m128i* o = reinterpret_cast<__m128i*>(out);
  const __m128i sum = _mm_add_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(g)), _mm_set1_epi16(q));
  _mm_storeu_si128(o, _mm_min_epi16(_mm_loadu_si128(o), sum));
#else
  for (int i = 0; i < 8; ++i) out[i] = std::min(out[i], static_cast<int16_t>(g[i] + q));
#endif
}

// The obstacles of row (y, z) of block b (block-local coordinates); a block never allocated is
// all unknown.
inline uint32_t row_obstacles(const map::VoxelBlock* b, int y, int z, bool unknown_is_obstacle) {
  if (!b) return unknown_is_obstacle ? 0xffffu : 0u;
  return obstacle_bits(&b->state[static_cast<size_t>((z << (2 * map::kBlockBits)) | (y << map::kBlockBits))],
                       unknown_is_obstacle);
}

// Bits x0..x1 of a block row.
inline uint32_t span_bits(int x0, int x1) { return ((uint32_t{1} << (x1 - x0 + 1)) - 1) << x0; }

// Calls f(x) for each set bit x, lowest first, while f returns true; false when it stopped.
template <class F>
bool each_bit(uint32_t bits, F&& f) {
  for (; bits; bits &= bits - 1)
    if (!f(__builtin_ctz(bits))) return false;
  return true;
}

// Calls row(y, z, bits, x_base) for each block row of the key box [kmin, kmax] that row_wanted(y,
// z) accepts, block by block: bits are its obstacles inside the box (occupied; unknown too when
// unknown_is_obstacle, including voxels of blocks never allocated), bit i for voxel x_base + i.
// With a branch per voxel the box checks were a tenth of DEP's cycle and the scan 30 % of an
// ESDF chunk fill's instructions. Stops and returns false when row does.
template <class RowWanted, class Row>
bool for_each_obstacle_row(const map::StateGrid& grid, const VoxelKey& kmin, const VoxelKey& kmax,
                           bool unknown_is_obstacle, RowWanted&& row_wanted, Row&& row) {
  const VoxelKey bmin = map::block_of(kmin), bmax = map::block_of(kmax);
  for (int32_t bz = bmin.z; bz <= bmax.z; ++bz) {
    for (int32_t by = bmin.y; by <= bmax.y; ++by) {
      for (int32_t bx = bmin.x; bx <= bmax.x; ++bx) {
        const map::VoxelBlock* b = grid.find_block({bx, by, bz});
        if (!b && !unknown_is_obstacle) continue;
        const VoxelKey base{bx * map::kBlockSize, by * map::kBlockSize, bz * map::kBlockSize};
        const int x0 = std::max(kmin.x, base.x) - base.x,
                  x1 = std::min(kmax.x, base.x + map::kBlockMask) - base.x;
        const int y0 = std::max(kmin.y, base.y) - base.y,
                  y1 = std::min(kmax.y, base.y + map::kBlockMask) - base.y;
        const int z0 = std::max(kmin.z, base.z) - base.z,
                  z1 = std::min(kmax.z, base.z + map::kBlockMask) - base.z;
        const uint32_t keep = span_bits(x0, x1);
        for (int z = z0; z <= z1; ++z) {
          for (int y = y0; y <= y1; ++y) {
            if (!row_wanted(base.y + y, base.z + z)) continue;
            const uint32_t bits = row_obstacles(b, y, z, unknown_is_obstacle) & keep;
            if (bits && !row(base.y + y, base.z + z, bits, base.x)) return false;
          }
        }
      }
    }
  }
  return true;
}

// Calls visit(x, y, z) for every obstacle voxel of the key box (as above), block by block, in
// order of x within a block row. Stops and returns false when visit returns false.
template <class RowWanted, class Visit>
bool for_each_obstacle(const map::StateGrid& grid, const VoxelKey& kmin, const VoxelKey& kmax,
                       bool unknown_is_obstacle, RowWanted&& row_wanted, Visit&& visit) {
  return for_each_obstacle_row(grid, kmin, kmax, unknown_is_obstacle, row_wanted,
                               [&](int32_t y, int32_t z, uint32_t bits, int32_t x_base) {
                                 return each_bit(bits, [&](int x) { return visit(x_base + x, y, z); });
                               });
}

// As for_each_obstacle, without row_wanted, but in the order of a loop over z, y, then x across
// the blocks (a sum over the visits comes out the same to the last bit as that loop's); each row
// of blocks is looked up once for all its voxel rows.
template <class Visit>
void for_each_obstacle_zyx(const map::StateGrid& grid, const VoxelKey& kmin, const VoxelKey& kmax,
                           bool unknown_is_obstacle, Visit&& visit) {
  const int32_t bx0 = map::block_of(kmin).x, bx1 = map::block_of(kmax).x;
  std::vector<const map::VoxelBlock*> blocks(static_cast<size_t>(bx1 - bx0 + 1));
  std::vector<uint32_t> keep(blocks.size());
  for (int32_t bx = bx0; bx <= bx1; ++bx) {
    const int base = bx * map::kBlockSize;
    keep[static_cast<size_t>(bx - bx0)] =
        span_bits(std::max(kmin.x, base) - base, std::min(kmax.x, base + map::kBlockMask) - base);
  }
  int32_t row_by = 0, row_bz = 0;
  bool looked = false;
  for (int32_t z = kmin.z; z <= kmax.z; ++z)
    for (int32_t y = kmin.y; y <= kmax.y; ++y) {
      const int32_t by = y >> map::kBlockBits, bz = z >> map::kBlockBits;
      if (!looked || by != row_by || bz != row_bz) {
        for (int32_t bx = bx0; bx <= bx1; ++bx)
          blocks[static_cast<size_t>(bx - bx0)] = grid.find_block({bx, by, bz});
        row_by = by;
        row_bz = bz;
        looked = true;
      }
      for (int32_t bx = bx0; bx <= bx1; ++bx) {
        const uint32_t bits = row_obstacles(blocks[static_cast<size_t>(bx - bx0)], y & map::kBlockMask,
                                            z & map::kBlockMask, unknown_is_obstacle) &
                              keep[static_cast<size_t>(bx - bx0)];
        each_bit(bits, [&](int x) {
          visit(bx * map::kBlockSize + x, y, z);
          return true;
        });
      }
    }
}

// What changes whenever the grid does (changes() alone could repeat after a grid was replaced).
std::array<uint64_t, 4> stamp_of(const map::StateGrid& g) {
  return {g.changes(), static_cast<uint64_t>(g.free_voxels()), static_cast<uint64_t>(g.occupied_voxels()),
          static_cast<uint64_t>(g.num_blocks())};
}

VoxelKey chunk_of(const VoxelKey& k) {
  return {k.x >> CollisionChecker::kChunkBits, k.y >> CollisionChecker::kChunkBits,
          k.z >> CollisionChecker::kChunkBits};
}

uint64_t pack(const VoxelKey& k) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(k.x) & 0x1fffff) << 42) |
         (static_cast<uint64_t>(static_cast<uint32_t>(k.y) & 0x1fffff) << 21) |
         (static_cast<uint64_t>(static_cast<uint32_t>(k.z) & 0x1fffff));
}
}  // namespace

void CollisionChecker::validate_cache() const {
  if (!grid_) return;
  const std::array<uint64_t, 4> stamp = stamp_of(*grid_);
  if (cache_grid_ == grid_ && stamp == cache_stamp_) return;
  for (auto& c : centre_cache_) c.clear();
  last_chunk_ = {};
  cache_grid_ = grid_;
  cache_stamp_ = stamp;
}

int CollisionChecker::reach_for(double cap, double res) {
  // Exact below cap + a voxel diagonal + half a voxel, which esdf() needs for `cap`; an obstacle
  // outside the searched cube is at least this many voxels away.
  return static_cast<int>(std::ceil((cap + std::sqrt(3.0) * res + 0.5 * res) / res));
}

void CollisionChecker::note_changes(const std::vector<map::VoxelChange>& changes) const {
  if (!cache_grid_ || changes.empty()) return;
  if (cache_grid_->changes() - cache_stamp_[0] > changes.size()) {
    // The grid made transitions that are not in `changes` (a map replaced whole, or a delta
    // this checker was not told of): nothing tells which values still hold, so none is kept.
    for (auto& c : centre_cache_) c.clear();
    last_chunk_ = {};
    cache_stamp_ = stamp_of(*cache_grid_);
    return;
  }
  // A change at v alters the values of centres within `reach` of it: the chunks that hold any
  // voxel of v ± reach. Per changed chunk, the bounding box of its changes grown by reach (3 or 4
  // chunks per axis, not the 5 of a chunk's whole neighbourhood).
  const int reach = reach_for(cache_cap_, cache_grid_->resolution());
  // Each cache sees its own obstacles: occupied voxels (rule 0) or everything not free (rule 1).
  // A change that keeps a voxel on the same side for a rule (unknown -> occupied for rule 1,
  // unknown -> free for rule 0: most changes at the edge of the known space) leaves that cache
  // as it is. Without the previous state, both go.
  auto matters = [](int rule, const map::VoxelChange& c) {
    if (!c.previous) return true;
    const VoxelState before = *c.previous, after = c.state;
    return rule == 0 ? (before == VoxelState::kOccupied) != (after == VoxelState::kOccupied)
                     : (before == VoxelState::kFree) != (after == VoxelState::kFree);
  };
  for (int rule = 0; rule < 2; ++rule) {
    std::unordered_map<uint64_t, std::pair<VoxelKey, VoxelKey>> boxes;
    for (const map::VoxelChange& c : changes) {
      if (!matters(rule, c)) continue;
      auto [it, inserted] = boxes.try_emplace(pack(chunk_of(c.key)), c.key, c.key);
      if (inserted) continue;
      for (int i = 0; i < 3; ++i) {
        it->second.first[i] = std::min(it->second.first[i], c.key[i]);
        it->second.second[i] = std::max(it->second.second[i], c.key[i]);
      }
    }
    for (const auto& [chunk, box] : boxes) {
      const VoxelKey lo = chunk_of({box.first.x - reach, box.first.y - reach, box.first.z - reach});
      const VoxelKey hi = chunk_of({box.second.x + reach, box.second.y + reach, box.second.z + reach});
      for (int32_t z = lo.z; z <= hi.z; ++z)
        for (int32_t y = lo.y; y <= hi.y; ++y)
          for (int32_t x = lo.x; x <= hi.x; ++x) centre_cache_[rule].erase(pack({x, y, z}));
    }
  }
  last_chunk_ = {};
  cache_stamp_ = stamp_of(*cache_grid_);  // what is left is true for the grid as it is now
}

double CollisionChecker::centre_value(const VoxelKey& c, bool unknown_is_obstacle) const {
  const VoxelKey chunk = chunk_of(c);
  const uint64_t key = pack(chunk);
  LastChunk& last = last_chunk_[unknown_is_obstacle ? 1 : 0];
  // Consecutive reads (the 8 corners of a point, the points of an edge) mostly share a chunk.
  if (!last.values || last.key != key) {
    auto [it, inserted] = centre_cache_[unknown_is_obstacle ? 1 : 0].try_emplace(key);
    if (inserted) fill_chunk(chunk, unknown_is_obstacle, it->second);
    last.key = key;
    last.values = &it->second;
  }
  return (*last.values)[static_cast<size_t>((c.x & kChunkMask) | ((c.y & kChunkMask) << kChunkBits) |
                                            ((c.z & kChunkMask) << (2 * kChunkBits)))];
}

void CollisionChecker::fill_chunk(const VoxelKey& chunk, bool unknown_is_obstacle, CacheChunk& out) const {
  // One exact distance transform over the chunk grown by the search reach (separable squared
  // distances: a binary pass along x, then lower envelopes along y and z, kept only for the
  // chunk's own voxels) gives every centre what centre_search would, capped at reach^2 the same
  // way: an obstacle that could lower a centre's value lies within the region. Cheaper than one
  // cube search per centre once a few dozen centres of a chunk are asked for, which an edge's
  // points 1 cm apart always do.
  const int reach = reach_for(cache_cap_, grid_->resolution());
  const int n = kChunkSize + 2 * reach;
  const int32_t cap2 = reach * reach;
  const VoxelKey o{chunk.x * kChunkSize - reach, chunk.y * kChunkSize - reach, chunk.z * kChunkSize - reach};
  // Each row (y, z) of the region as a mask of its obstacle voxels, bit x for o.x + x, read from
  // the states sixteen at a time; then each of the chunk's columns finds its nearest obstacle in
  // the row by counting bits. A byte per voxel, set by visiting the obstacles one by one and
  // scanned both ways per row, was 60 % of a fill's instructions.
  if (n > 64) {  // rows wider than a mask (resolutions finer than ~3 cm): one search per centre
    for (int i = 0; i < kChunkVolume; ++i) {
      const VoxelKey c{chunk.x * kChunkSize + (i & kChunkMask),
                       chunk.y * kChunkSize + ((i >> kChunkBits) & kChunkMask),
                       chunk.z * kChunkSize + (i >> (2 * kChunkBits))};
      out[static_cast<size_t>(i)] = centre_search(c, reach, unknown_is_obstacle);
    }
    return;
  }
  std::vector<uint64_t>& rows = fill_scratch_.rows;
  rows.assign(static_cast<size_t>(n) * n, 0);
  for_each_obstacle_row(
      *grid_, o, {o.x + n - 1, o.y + n - 1, o.z + n - 1}, unknown_is_obstacle,
      [](int32_t, int32_t) { return true; },
      [&](int32_t y, int32_t z, uint32_t bits, int32_t x_base) {
        const int shift = x_base - o.x;  // block x to region x
        rows[static_cast<size_t>(z - o.z) * n + (y - o.y)] |=
            shift >= 0 ? static_cast<uint64_t>(bits) << shift : static_cast<uint64_t>(bits) >> -shift;
        return true;
      });
  // gx[z][y][i]: squared x distance from the chunk's column i to the nearest obstacle of row (y, z).
  // Rows and planes with nothing below the cap are skipped by the later passes.
  std::vector<int16_t>& gx = fill_scratch_.gx;
  const int16_t cap16 = static_cast<int16_t>(cap2);
  std::vector<uint8_t>& row_near = fill_scratch_.row_near;
  gx.assign(static_cast<size_t>(n) * n * kChunkSize, cap16);
  row_near.assign(static_cast<size_t>(n) * n, 0);
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint64_t m = rows[r];
    if (m == 0) continue;
    row_near[r] = 1;
    int16_t* g = &gx[r * kChunkSize];
    // Obstacles at all of the chunk's columns (unknown space behind a wall): every distance is 0.
    if (((m >> reach) & 0xffu) == 0xffu) {
      std::fill(g, g + kChunkSize, int16_t{0});
      continue;
    }
    for (int i = 0; i < kChunkSize; ++i) {
      const int c = reach + i;  // < n <= 64
      const uint64_t low = m & (c >= 63 ? ~uint64_t{0} : (uint64_t{2} << c) - 1), high = m >> c;
      const int left = low ? c - (63 - __builtin_clzll(low)) : 2 * n;
      const int right = high ? __builtin_ctzll(high) : 2 * n;
      const int32_t d = std::min(left, right);
      g[i] = static_cast<int16_t>(std::min(cap2, d * d));
    }
  }
  // gy[z][j][i]: min over y of gx + (y - y_j)^2.
  std::vector<int16_t>& gy = fill_scratch_.gy;
  std::vector<uint8_t>& plane_near = fill_scratch_.plane_near;
  gy.assign(static_cast<size_t>(n) * kChunkSize * kChunkSize, cap16);
  plane_near.assign(static_cast<size_t>(n), 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y) {
      if (!row_near[static_cast<size_t>(z) * n + y]) continue;
      plane_near[static_cast<size_t>(z)] = 1;
      const int16_t* g = &gx[(static_cast<size_t>(z) * n + y) * kChunkSize];
      for (int j = 0; j < kChunkSize; ++j) {
        const int32_t dy = y - (reach + j), q = dy * dy;
        if (q >= cap2) continue;
        min_plus_row(&gy[(static_cast<size_t>(z) * kChunkSize + j) * kChunkSize], g, static_cast<int16_t>(q));
      }
    }
  // Along z, straight into the chunk's values.
  const double res = grid_->resolution();
  std::array<int16_t, kChunkVolume> best;
  best.fill(cap16);
  for (int z = 0; z < n; ++z) {
    if (!plane_near[static_cast<size_t>(z)]) continue;
    const int16_t* g = &gy[static_cast<size_t>(z) * kChunkSize * kChunkSize];
    for (int k = 0; k < kChunkSize; ++k) {
      const int32_t dz = z - (reach + k), q = dz * dz;
      if (q >= cap2) continue;
      int16_t* b = &best[static_cast<size_t>(k) * kChunkSize * kChunkSize];
      for (int i = 0; i < kChunkSize * kChunkSize; i += kChunkSize)
        min_plus_row(b + i, g + i, static_cast<int16_t>(q));
    }
  }
  for (int i = 0; i < kChunkVolume; ++i)
    out[i] = map::esdf_value(std::sqrt(static_cast<double>(best[i])), res);
}

double CollisionChecker::centre_search(const VoxelKey& c, int reach, bool unknown_is_obstacle) const {
  int64_t best2 = static_cast<int64_t>(reach) * reach;
  const VoxelKey kmin{c.x - reach, c.y - reach, c.z - reach}, kmax{c.x + reach, c.y + reach, c.z + reach};
  for_each_obstacle(
      *grid_, kmin, kmax, unknown_is_obstacle,
      [&](int32_t y, int32_t z) {
        const int64_t dy = y - c.y, dz = z - c.z;
        return dy * dy + dz * dz < best2;
      },
      [&](int32_t x, int32_t y, int32_t z) {
        const int64_t dx = x - c.x, dy = y - c.y, dz = z - c.z;
        best2 = std::min(best2, dx * dx + dy * dy + dz * dz);
        return true;
      });
  const double res = grid_->resolution();
  return map::esdf_value(std::sqrt(static_cast<double>(best2)), res);
}

bool CollisionChecker::region_free(const Eigen::Vector3d& p, const Eigen::Vector3d& half, double radius,
                                   bool unknown_is_occupied) const {
  ++box_checks_;
  if (!grid_ || !p.allFinite()) return false;
  const double res = grid_->resolution(), inv = 1.0 / res;
  const Eigen::Vector3d reach = half.cwiseMax(Eigen::Vector3d::Constant(radius));
  VoxelKey kmin, kmax;
  for (int i = 0; i < 3; ++i) {
    const double a = std::floor((p[i] - reach[i]) * inv);
    const double b = std::ceil((p[i] + reach[i]) * inv) - 1.0;
    if (std::abs(a) >= map::kMaxKeyMagnitude || std::abs(b) >= map::kMaxKeyMagnitude) return false;
    kmin[i] = static_cast<int32_t>(a);
    kmax[i] = static_cast<int32_t>(b);
  }
  const double r2 = radius * radius;
  // A voxel that is not free blocks when it overlaps the open box or its cube is within radius.
  auto blocks = [&](int32_t x, int32_t y, int32_t z) {
    const double v0[3] = {x * res, y * res, z * res};
    bool in_box = true;
    double d2 = 0.0;
    const int32_t k[3] = {x, y, z};
    for (int i = 0; i < 3; ++i) {
      const double lo = v0[i], hi = (k[i] + 1) * res;
      if (!(lo < p[i] + half[i] && hi > p[i] - half[i])) in_box = false;
      const double d = p[i] < lo ? lo - p[i] : (p[i] > hi ? p[i] - hi : 0.0);
      d2 += d * d;
    }
    return in_box || (radius > 0 && d2 < r2);
  };
  return for_each_obstacle(
      *grid_, kmin, kmax, unknown_is_occupied, [](int32_t, int32_t) { return true; },
      [&](int32_t x, int32_t y, int32_t z) { return !blocks(x, y, z); });
}

double CollisionChecker::esdf(const Eigen::Vector3d& p, double cap, bool unknown_is_obstacle) const {
  ++box_checks_;
  if (!grid_ || !p.allFinite()) return -1.0;
  const double res = grid_->resolution(), inv = 1.0 / res;
  // The point in centre coordinates (voxel k's centre at u = k), far enough from the keys' limit
  // that every corner and its search stay valid.
  double u[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = p[i] * inv - 0.5;
    if (std::abs(std::floor(u[i])) >= map::kMaxKeyMagnitude - 64) return -1.0;
  }
  // Corner values differ by at most a voxel diagonal, so when the result is below cap every
  // corner is below cap + diagonal, which a centre's search of reach_for(cap) finds exactly;
  // above it the search's lower bound stands in. The cache serves every cap the checks use.
  const bool cached = cap <= cache_cap_;
  if (cached) validate_cache();
  const int reach = cached ? 0 : reach_for(cap, res);
  // The field has no border: every voxel's value is computed from the states around it (an
  // obstacle voxel itself reads -half a voxel, which fails every positive requirement).
  const int unbounded[3] = {0, 0, 0};
  return map::trilinear_distance(u, unbounded, inv, [&](int x, int y, int z) {
    const VoxelKey k{x, y, z};
    return cached ? centre_value(k, unknown_is_obstacle) : centre_search(k, reach, unknown_is_obstacle);
  });
}

bool CollisionChecker::clear(const Eigen::Vector3d& p, const Eigen::Vector3d& half, double distance) const {
  // The box keeps the body (plus margin) off obstacle voxels at its corners, which a distance
  // bound of the body's half width does not.
  if (!region_free(p, half, 0.0, true)) return false;
  return esdf(p, distance) >= distance;
}

bool CollisionChecker::node_free(const Eigen::Vector3d& p) const {
  return clear(p, body_half_, config_.clearance);
}

bool CollisionChecker::passage_free(const Eigen::Vector3d& p) const {
  // Only the bare body box: in a 7-voxel gap (a 0.9 m door with both jambs grown by a voxel)
  // the box plus margin touches the jambs at the slightest offset; door_clearance decides.
  return clear(p, vehicle_half_, config_.door_clearance);
}

bool CollisionChecker::vehicle_free(const Eigen::Vector3d& p) const {
  return region_free(p, vehicle_half_, 0.0, false);
}

bool CollisionChecker::centre(Eigen::Vector3d& p, int iterations, double max_step, bool passage) const {
  if (!grid_ || !p.allFinite()) return false;
  const double res = grid_->resolution(), inv = 1.0 / res;
  // Pushed by cube distances, kept by the ESDF value, which can read up to half a voxel less
  // (centre distances, interpolated): push until the cubes are that much farther.
  const double r = (passage ? config_.door_clearance : config_.clearance) + 0.5 * res;
  auto ok = [&](const Eigen::Vector3d& q) { return passage ? passage_free(q) : node_free(q); };
  for (int it = 0; it < iterations; ++it) {
    if (ok(p)) return true;
    ++box_checks_;
    VoxelKey kmin, kmax;
    for (int i = 0; i < 3; ++i) {
      kmin[i] = static_cast<int32_t>(std::floor((p[i] - reach_[i]) * inv));
      kmax[i] = static_cast<int32_t>(std::ceil((p[i] + reach_[i]) * inv)) - 1;
    }
    Eigen::Vector3d push = Eigen::Vector3d::Zero();
    for_each_obstacle_zyx(*grid_, kmin, kmax, true, [&](int32_t x, int32_t y, int32_t z) {
      const Eigen::Vector3d lo(x * res, y * res, z * res);
      const Eigen::Vector3d q = p.cwiseMax(lo).cwiseMin(lo + Eigen::Vector3d::Constant(res));
      const Eigen::Vector3d v = p - q;
      const double d = v.norm();
      if (d >= r || d < 1e-9) return;
      push += (r - d) * v / d;
    });
    const double n = push.norm();
    if (n < 1e-9) return false;  // inside an obstacle or pushed equally from all sides
    // How far to go along the push: where the ESDF value peaks within max_step. The summed push
    // grows with the number of voxels in reach and overshoots a doorway's middle (the only
    // place a 0.9 m gap has the passage clearance) back and forth; the peak is that middle.
    const Eigen::Vector3d u = push / n;
    const double want = r + res;
    double best_t = std::min(n, max_step), best_v = esdf(p + best_t * u, want);
    for (double t = kFineStep; t <= max_step + 1e-9; t += kFineStep) {
      const double v = esdf(p + t * u, want);
      if (v > best_v + 1e-9) best_v = v, best_t = t;
    }
    p += best_t * u;
  }
  return ok(p);
}

bool CollisionChecker::centre_line_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        double skip_radius) const {
  if (!grid_) return false;
  map::StateGrid::Reader r = grid_->reader();
  const double skip2 = skip_radius * skip_radius;
  const map::KeyMath& km = grid_->keys();
  return map::traverse_segment(km, a, b, [&](const VoxelKey& k) {
    const VoxelState s = r.state(k);
    if (s == VoxelState::kFree) return true;
    if (s == VoxelState::kOccupied) return false;
    // Unknown: tolerated only near the root (escape).
    return skip2 > 0 && (km.center(k) - a).squaredNorm() < skip2;
  });
}

bool CollisionChecker::samples_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    double escape_radius) const {
  const double length = (b - a).norm();
  if (length < 1e-9) return true;
  // Along the edge the interpolated field changes at most |u|_1 per metre (each axis's partial
  // derivative is a mix of neighbour differences, each at most one voxel per voxel), so a point
  // whose value exceeds passage_clearance by |u|_1 * h / 2 vouches for the h / 2 on either side:
  // every point of the edge, not only the samples, keeps what the controller checks.
  const double slope = ((b - a) / length).lpNorm<1>();
  // The bare box swept over a stretch of half length `half` lies in the box grown by this times
  // `half`: a doorway point vouches for its stretch with it, as the ESDF's slope does. The box at
  // the point alone let its corner, 0.354 m from the centre, touch a wall's end between two fine
  // points that both kept door_clearance (0.34 m): a collision in the closed loop.
  const Eigen::Vector3d sweep = ((b - a) / length).cwiseAbs();
  const int n = std::max(1, static_cast<int>(std::ceil(length / config_.edge_step)));
  const double h = length / n;
  const int fine = std::max(1, static_cast<int>(std::ceil(h / kFineStep)));
  // Where an edge comes closer than passage_clearance (down to door_clearance) counts toward
  // door_length: a doorway's crossing, not a flight along a wall.
  double door = 0.0;
  auto at = [&](double s) { return a + (s / length) * (b - a); };
  // Near the root, as the controller lets a start below its bound move out (allow_escape): a point
  // whose bare box overlaps an occupied voxel still passes if it is no closer to the obstacles (in
  // the controller's measure) than the root itself, and farther than the body's half width. A
  // vehicle that braked with its box's corner touching a voxel of a door leaf was otherwise cut off
  // from every node, 0.17 m away or not, and DONE at 39 % (env3, dep, seed 4, at 26 s).
  // A root below the half width (its body touches, or its box overlaps the voxels of what it
  // touches) may leave as the controller lets it (ClearanceRule::contact_rise): its floor starts
  // at the root's own value and rises by kContactRise per metre until the half width, so the edge
  // moves away and never along the obstacle. A vehicle that touched a chair (ESDF 0.207 m) had no
  // edge and no path for the 225 s left of its run (env3, fuel's latency tour, seed 1).
  const double root_value = escape_radius > 0 ? esdf(a, config_.passage_clearance, false) : 0.0;
  const bool contact = escape_radius > 0 && root_value < vehicle_half_.x();
  const double floor = escape_radius > 0 ? std::max(vehicle_half_.x(), root_value - kEscapeSlack) : 0.0;
  const auto escapes = [&](const Eigen::Vector3d& p, double s) {
    if (vehicle_free(p)) return true;
    const double need =
        contact ? std::min(vehicle_half_.x(), root_value - kEscapeSlack + kContactRise * s) : floor;
    return esdf(p, config_.passage_clearance, false) >= need;
  };
  // 2: the stretch of `half` around s keeps passage_clearance; 1: door_clearance; 0: neither.
  auto level = [&](double s, double half) {
    const Eigen::Vector3d p = at(s);
    if (escape_radius > 0 && s < escape_radius) return escapes(p, s) ? 2 : 0;
    const double v = esdf(p, config_.passage_clearance + slope * half);
    if (v >= config_.passage_clearance + slope * half && region_free(p, body_half_, 0.0, true)) return 2;
    // Doorway level: door_clearance as the controller sees it, to occupied voxels only, and
    // kDoorUnknownClearance counting unknown ones too. Jambs seen at grazing angles leave unknown
    // voxels that closed doorways the vehicle had flown through (env3 stayed at 84 % with them
    // counted in full); centre_line_free and door_length keep edges out of unknown space.
    if (!region_free(p, vehicle_half_ + half * sweep, 0.0, true)) return 0;
    const double need = config_.door_clearance + slope * half;
    if (esdf(p, need, false) < need) return 0;
    return esdf(p, kDoorUnknownClearance + slope * half) >= kDoorUnknownClearance + slope * half ? 1 : 0;
  };
  // Coarse points first (each vouching for h / 2 around it, with a larger excess); where one
  // falls short, the points kFineStep apart within its stretch decide (doorways, along walls).
  for (int i = 0; i <= n; ++i) {
    const double s = i * h;
    const double lo = std::max(0.0, s - 0.5 * h), hi = std::min(length, s + 0.5 * h);
    if (level(s, 0.5 * h) == 2) continue;
    const double hf = (hi - lo) / fine;
    for (int j = 0; j < fine; ++j) {
      const int l = level(lo + (j + 0.5) * hf, 0.5 * hf);
      if (l == 0) return false;
      if (l == 1 && (door += hf) > config_.door_length + 1e-9) return false;
    }
  }
  return true;
}

bool CollisionChecker::edge_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  if (!a.allFinite() || !b.allFinite()) return false;
  if (!centre_line_free(a, b, 0.0)) return false;
  return samples_free(a, b, 0.0);
}

bool CollisionChecker::root_edge_free(const Eigen::Vector3d& root, const Eigen::Vector3d& b) const {
  if (!root.allFinite() || !b.allFinite()) return false;
  // The escape rule only where it is needed: a root that has the clearance gets the full check.
  if (node_free(root)) return edge_free(root, b);
  if (!centre_line_free(root, b, config_.root_escape_radius)) return false;
  return samples_free(root, b, config_.root_escape_radius);
}

}  // namespace semx::planner
