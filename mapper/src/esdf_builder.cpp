#include "semx/mapper/esdf_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "semx/map/esdf_distance.hpp"

namespace semx::mapper {

namespace {

// Values at or above this are "no site on this line" (kEdtInfinity, possibly plus a square).
constexpr float kFiniteBelow = 1.0e17f;
// Linear distances along the first axis saturate here; squared, it becomes kEdtInfinity.
constexpr float kLinearInfinity = 1.0e9f;

// 1-D squared distance transform of a sampled function (Felzenszwalb & Huttenlocher 2012),
// building the lower envelope from finite samples only, so "no site" never enters the
// intersection arithmetic. Finite samples are sums of squared voxel offsets, whole numbers, so the
// envelope is kept in integers: each intersection is the fraction zn / zd, compared by
// cross-multiplying. That is exact, where a float quotient is rounded, and it spares the division
// and the int-to-float conversions: the mapper's CPU in an env2 process set fell by about a
// fifth (docs/mapper.md, "ESDF"). Window sides are at most 10^4 voxels (MapperConfig), so
// the products stay far below 2^63.
void edt_1d(const float* f, int n, float* d, EdtWorkspace& w) {
  int* v = w.v.data();
  int64_t* fv = w.fv.data();
  int64_t* zn = w.zn.data();
  int64_t* zd = w.zd.data();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!(f[q] < kFiniteBelow)) continue;
    const int64_t fq = static_cast<int64_t>(f[q]) + static_cast<int64_t>(q) * q;
    // Pop the parabolas the new one hides: s <= z[k], s = (fq - fp) / (2 (q - p)). The first
    // parabola's z is -infinity: it is never popped.
    while (k > 0) {
      const int64_t num = fq - fv[k];
      const int64_t den = 2 * static_cast<int64_t>(q - v[k]);
      if (num * zd[k] > zn[k] * den) break;
      --k;
    }
    ++k;
    v[k] = q;
    fv[k] = fq;
    if (k > 0) {
      zn[k] = fq - fv[k - 1];
      zd[k] = 2 * static_cast<int64_t>(q - v[k - 1]);
    }
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kEdtInfinity;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (j < k && zn[j + 1] < static_cast<int64_t>(q) * zd[j + 1]) ++j;
    const int64_t dq = q - v[j];
    // fv - v^2 is the sample itself, read back from the envelope.
    d[q] = static_cast<float>(dq * dq + fv[j] - static_cast<int64_t>(v[j]) * v[j]);
  }
}

}  // namespace

void squared_edt(const uint8_t* site, uint8_t want, int nx, int ny, int nz, float* out, EdtWorkspace& work) {
  const size_t plane = static_cast<size_t>(nx) * ny;
  const size_t longest = static_cast<size_t>(std::max({nx, ny, nz}));
  work.line_in.resize(longest);
  work.line_out.resize(longest);
  work.v.resize(longest);
  work.fv.resize(longest);
  work.zn.resize(longest);
  work.zd.resize(longest);
  float* line_in = work.line_in.data();
  float* line_out = work.line_out.data();

  // z first, as plane-wide linear sweeps: contiguous and vectorisable, and a binary image needs
  // no parabolas on its first axis.
  for (size_t i = 0; i < plane; ++i) out[i] = site[i] == want ? 0.0f : kLinearInfinity;
  for (int z = 1; z < nz; ++z) {
    const uint8_t* s = site + z * plane;
    float* o = out + z * plane;
    const float* prev = o - plane;
    for (size_t i = 0; i < plane; ++i) o[i] = s[i] == want ? 0.0f : std::min(prev[i] + 1.0f, kLinearInfinity);
  }
  for (int z = nz - 2; z >= 0; --z) {
    float* o = out + z * plane;
    const float* next = o + plane;
    for (size_t i = 0; i < plane; ++i) o[i] = std::min(o[i], next[i] + 1.0f);
  }
  const size_t total = plane * nz;
  for (size_t i = 0; i < total; ++i) out[i] = out[i] >= kLinearInfinity ? kEdtInfinity : out[i] * out[i];

  // x: contiguous lines. A line that is all sites is final (0 everywhere): the inside field
  // (want = free) of a mostly free window is mostly such lines, and skipping them halves its cost.
  for (size_t line = 0; line < static_cast<size_t>(ny) * nz; ++line) {
    float* o = out + line * nx;
    if (std::all_of(o, o + nx, [](float v) { return v == 0.0f; })) continue;
    edt_1d(o, nx, line_out, work);
    std::memcpy(o, line_out, sizeof(float) * nx);
  }
  // y: strided lines, gathered; a plane (nx*ny floats) stays in cache while its lines are done.
  for (int z = 0; z < nz; ++z) {
    float* base = out + z * plane;
    for (int x = 0; x < nx; ++x) {
      bool any = false, positive = false;
      for (int y = 0; y < ny; ++y) {
        line_in[y] = base[x + static_cast<size_t>(nx) * y];
        any |= line_in[y] < kFiniteBelow;
        positive |= line_in[y] > 0.0f;
      }
      if (!any || !positive) continue;  // all infinite, or all sites: nothing changes
      edt_1d(line_in, ny, line_out, work);
      for (int y = 0; y < ny; ++y) base[x + static_cast<size_t>(nx) * y] = line_out[y];
    }
  }
}

EsdfBuilder::EsdfBuilder(const EsdfParams& params, double resolution) : params_(params) {
  grid_.resolution = resolution;
  grid_.max_distance = params.max_distance;
  grid_.unknown_as_occupied = params.unknown_as_occupied;
  int* dims[3] = {&grid_.nx, &grid_.ny, &grid_.nz};
  for (int a = 0; a < 3; ++a) {
    const double w = a < static_cast<int>(params.window.size()) ? params.window[a] : 2.0 * resolution;
    *dims[a] = std::max(2, static_cast<int>(std::lround(w / resolution)));
  }
}

map::VoxelKey EsdfBuilder::window_origin(const Eigen::Vector3d& center) const {
  const map::KeyMath km(grid_.resolution);
  const map::VoxelKey c = km.key(center);
  return {c.x - grid_.nx / 2, c.y - grid_.ny / 2, c.z - grid_.nz / 2};
}

bool EsdfBuilder::update(const map::StateGrid& grid, const Eigen::Vector3d& center,
                         const map::KeyBox& changed, int64_t map_seq, bool force) {
  map::VoxelKey probe;
  if (!map::KeyMath(grid_.resolution).key(center, probe)) return false;
  const map::VoxelKey origin = window_origin(center);
  map::KeyBox window;
  window.min = origin;
  window.max = origin + map::VoxelKey{grid_.nx - 1, grid_.ny - 1, grid_.nz - 1};
  const bool recompute = force || grid_.empty() || origin != grid_.origin || changed.intersects(window);
  grid_.map_seq = map_seq;
  if (!recompute) return false;
  grid_.origin = origin;
  compute(grid);
  return true;
}

void EsdfBuilder::compute(const map::StateGrid& grid) {
  const int nx = grid_.nx, ny = grid_.ny, nz = grid_.nz;
  const size_t n = static_cast<size_t>(nx) * ny * nz;
  obstacle_.resize(n);
  pos_.resize(n);
  neg_.resize(n);
  grid_.distance.resize(n);
  const uint8_t unknown_value = params_.unknown_as_occupied ? 1 : 0;

  // Block by block: one hash lookup per block of the window.
  const map::VoxelKey o = grid_.origin;
  const map::VoxelKey last = o + map::VoxelKey{nx - 1, ny - 1, nz - 1};
  const map::VoxelKey bmin = map::block_of(o), bmax = map::block_of(last);
  for (int32_t bz = bmin.z; bz <= bmax.z; ++bz) {
    for (int32_t by = bmin.y; by <= bmax.y; ++by) {
      for (int32_t bx = bmin.x; bx <= bmax.x; ++bx) {
        const map::VoxelBlock* b = grid.find_block({bx, by, bz});
        const map::VoxelKey base{bx * map::kBlockSize, by * map::kBlockSize, bz * map::kBlockSize};
        const int x0 = std::max(o.x, base.x), x1 = std::min(last.x, base.x + map::kBlockMask);
        const int y0 = std::max(o.y, base.y), y1 = std::min(last.y, base.y + map::kBlockMask);
        const int z0 = std::max(o.z, base.z), z1 = std::min(last.z, base.z + map::kBlockMask);
        for (int z = z0; z <= z1; ++z) {
          for (int y = y0; y <= y1; ++y) {
            uint8_t* dst = &obstacle_[grid_.index(x0 - o.x, y - o.y, z - o.z)];
            if (!b) {
              std::memset(dst, unknown_value, x1 - x0 + 1);
              continue;
            }
            const map::VoxelState* row =
                &b->state[((y - base.y) << map::kBlockBits) | ((z - base.z) << (2 * map::kBlockBits))];
            for (int x = x0; x <= x1; ++x) {
              const map::VoxelState s = row[x - base.x];
              dst[x - x0] =
                  s == map::VoxelState::kOccupied ? 1 : (s == map::VoxelState::kUnknown ? unknown_value : 0);
            }
          }
        }
      }
    }
  }

  squared_edt(obstacle_.data(), 1, nx, ny, nz, pos_.data(), edt_work_);
  if (search_budget_ > 0.0) {
    inside_distances();
  } else {
    inside_transform();
  }
  // One square root per voxel of pos + neg: an obstacle voxel is a site of the outside field
  // (pos = 0) and a voxel outside obstacles one of the inside field (neg = 0; the search leaves
  // it so too), so the sum is exactly the one that applies, and the sign is a factor of +-1. Both
  // exact, so the values are those of a branch per voxel; without the branch the loop vectorises
  // (sqrtps is correctly rounded like sqrtss). This file is built with -fno-math-errno
  // (mapper/CMakeLists.txt): with errno every square root tests its result and may call libm.
  // One voxel at a time, this loop was about a tenth of the ESDF's time (perf).
  const float res = static_cast<float>(grid_.resolution);
  const float dmax = static_cast<float>(params_.max_distance);
  const uint8_t* ob = obstacle_.data();
  const float* pos = pos_.data();
  const float* neg = neg_.data();
  float* out = grid_.distance.data();
  for (size_t i = 0; i < n; ++i) {
    const float sign = static_cast<float>(1 - 2 * static_cast<int>(ob[i]));
    const float d = sign * map::esdf_value(std::sqrt(pos[i] + neg[i]), res);
    out[i] = std::min(std::max(d, -dmax), dmax);
  }
}

void EsdfBuilder::inside_transform() {
  squared_edt(obstacle_.data(), 0, grid_.nx, grid_.ny, grid_.nz, neg_.data(), edt_work_);
  last_inside_transform_ = true;
}

void EsdfBuilder::inside_distances() {
  const int nx = grid_.nx, ny = grid_.ny, nz = grid_.nz;
  const size_t plane = static_cast<size_t>(nx) * ny;
  const size_t n = plane * nz;
  const uint8_t* ob = obstacle_.data();
  float* neg = neg_.data();
  // A camera sees surfaces: most obstacle voxels touch a non-obstacle voxel across a face, which
  // puts them at the smallest non-zero squared distance, 1, exactly. Only the others ("deep")
  // need a search.
  deep_.clear();
  // Each deep voxel costs at least the 5^3 cube of the first search: past this many the budget
  // is spent for sure, and the scan stops there.
  int64_t budget = static_cast<int64_t>(search_budget_ * static_cast<double>(n));
  const size_t max_deep = static_cast<size_t>(budget / 125);
  for (int z = 0; z < nz && deep_.size() <= max_deep; ++z) {
    for (int y = 0; y < ny; ++y) {
      const size_t row = static_cast<size_t>(y) * nx + z * plane;
      for (int x = 0; x < nx; ++x) {
        const size_t i = row + x;
        if (!ob[i]) {
          neg[i] = 0.0f;  // read by compute(): its inside distance, 0 (see there)
          continue;
        }
        const bool shell = (x > 0 && !ob[i - 1]) || (x + 1 < nx && !ob[i + 1]) || (y > 0 && !ob[i - nx]) ||
                           (y + 1 < ny && !ob[i + nx]) || (z > 0 && !ob[i - plane]) ||
                           (z + 1 < nz && !ob[i + plane]);
        if (shell) {
          neg[i] = 1.0f;
        } else {
          deep_.push_back(static_cast<uint32_t>(i));
        }
      }
    }
  }
  last_inside_transform_ = false;
  if (deep_.size() > max_deep) {
    inside_transform();
    return;
  }
  if (deep_.empty()) return;

  // Deep voxels: the nearest non-obstacle voxel by growing cubes around each, stopped once the
  // next cube cannot hold a closer one, or once nothing closer can survive the clamp. A thick
  // block (unknown space counted as an obstacle) would make that cost (2 depth + 1)^3 per voxel:
  // past the budget the full transform is cheaper and is run instead (semx-perf-mapper measures
  // both).
  const double clamp_r = params_.max_distance / grid_.resolution + 0.5;  // sqrt(d2) beyond: clamped
  const int max_shell = static_cast<int>(std::ceil(clamp_r)) + 1;
  const double clamp_d2 = clamp_r * clamp_r;
  for (const uint32_t i : deep_) {
    const int x = static_cast<int>(i % nx), y = static_cast<int>((i / nx) % ny),
              z = static_cast<int>(i / plane);
    int64_t best = std::numeric_limits<int64_t>::max();
    for (int r = 2; r <= max_shell; ++r) {
      // Shell r: the cube of Chebyshev radius r minus the one of radius r - 1 (radius 1 holds
      // only obstacles across faces; its edges and corners are searched with shell 2's cube).
      const int z0 = std::max(0, z - r), z1 = std::min(nz - 1, z + r);
      const int y0 = std::max(0, y - r), y1 = std::min(ny - 1, y + r);
      const int x0 = std::max(0, x - r), x1 = std::min(nx - 1, x + r);
      for (int zz = z0; zz <= z1; ++zz) {
        const int dz = zz - z;
        for (int yy = y0; yy <= y1; ++yy) {
          const int dy = yy - y;
          const bool inner_row = r > 2 && std::abs(dz) < r && std::abs(dy) < r;
          const uint8_t* rowp = ob + static_cast<size_t>(yy) * nx + zz * plane;
          for (int xx = x0; xx <= x1; ++xx) {
            const int dx = xx - x;
            // Inside the previous cube: already searched (shell 2 searches its whole cube).
            if (inner_row && std::abs(dx) < r) {
              xx = x + r - 1;
              continue;
            }
            if (rowp[xx]) continue;
            const int64_t d2 =
                static_cast<int64_t>(dx) * dx + static_cast<int64_t>(dy) * dy + static_cast<int64_t>(dz) * dz;
            best = std::min(best, d2);
          }
        }
        budget -= static_cast<int64_t>(y1 - y0 + 1) * (x1 - x0 + 1);
      }
      // Voxels outside cube r are at least r + 1 away.
      if (best <= static_cast<int64_t>(r + 1) * (r + 1)) break;
      if (static_cast<double>(r + 1) * (r + 1) > clamp_d2) break;
      if (budget < 0) break;
    }
    if (budget < 0) {
      inside_transform();
      return;
    }
    neg[i] = best == std::numeric_limits<int64_t>::max() ? kEdtInfinity : static_cast<float>(best);
  }
}

}  // namespace semx::mapper
