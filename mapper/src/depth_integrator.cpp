#include "semx/mapper/depth_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace semx::mapper {

namespace {

// Scratch marks, one byte per voxel of the frustum's bounding box.
constexpr uint8_t kWalked = 1;  // observed this frame: a ray passed through or ended in it
constexpr uint8_t kHit = 2;     // a valid return of this frame ended in it
// Bit 2 + q: a ray was walked from an end point in quadrant q of the voxel (its halves along the
// two axes most across the ray; see end_points_row).
constexpr uint8_t kEndQuadrant0 = 4;
constexpr uint8_t kAnyEnd = 0x3C;
constexpr uint8_t kNearHit = 0x40;  // a valid return of this frame within hold_range ended in it

// Ray parameters t in [0, 1] as 32.32 fixed point; "never" is far beyond any reachable sum.
constexpr double kFixedOne = 4294967296.0;
constexpr int64_t kFixedInfinity = int64_t{1} << 60;
constexpr double kFixedInfinityD = 1152921504606846976.0;  // 2^60

// Pixel outcomes (index into the per-frame counters).
constexpr uint8_t kInvalid = 0;
constexpr uint8_t kHitReturn = 1;
constexpr uint8_t kNoReturn = 2;
constexpr uint8_t kBeyond = 3;
constexpr uint8_t kTooNear = 4;

// Largest frustum bounding box, in voxels per axis, the scratch grid may span (1024^3 bytes at
// most; a 90 degree camera at 250 voxels of range needs ~510).
constexpr double kMaxScratchExtent = 1020.0;

// Poses further out than this are garbage, not a place a quadrotor can be.
constexpr double kMaxWorldCoordinate = 1.0e5;

int ceil_log2(int64_t n) {
  int s = 0;
  while ((int64_t{1} << s) < n) ++s;
  return s;
}

// The per-pixel stage, written without branches or short-circuits and split by element width so
// that GCC vectorises both loops (kept out of line: inlined into the frame loop, it does not).
__attribute__((noinline)) void classify_row(const uint16_t* __restrict raw_row, int n, float zmin, float zmax,
                                            uint8_t* __restrict kind, float* __restrict z_out,
                                            int64_t* counts) {
  int invalid = 0, no_return = 0, beyond = 0, near = 0;
  for (int j = 0; j < n; ++j) {
    const int raw = raw_row[j];
    const float z = static_cast<float>(raw) * 0.001f;
    const int is_invalid = raw == runtime::kDepthInvalid;
    const int is_no_return = raw == runtime::kDepthNoReturn;
    const int is_beyond = (z > zmax) & (1 - is_no_return);
    const int is_near = (z < zmin) & (1 - is_invalid);
    kind[j] = static_cast<uint8_t>((kHitReturn + (kNoReturn - kHitReturn) * is_no_return +
                                    (kBeyond - kHitReturn) * is_beyond + (kTooNear - kHitReturn) * is_near) *
                                   (1 - is_invalid));
    z_out[j] = (is_no_return | is_beyond) ? zmax : z;
    invalid += is_invalid;
    no_return += is_no_return;
    beyond += is_beyond;
    near += is_near;
  }
  counts[kInvalid] += invalid;
  counts[kNoReturn] += no_return;
  counts[kBeyond] += beyond;
  counts[kTooNear] += near;
  counts[kHitReturn] += n - invalid - no_return - beyond - near;
}

// End points in scratch voxel units, their cells, and their quadrant: rays ending in different
// halves of a voxel across the ray take different ways back to the camera, while where along
// the ray they end matters little.
__attribute__((noinline)) void end_points_row(const float* __restrict z, const float* __restrict column_x,
                                              int n, float camx, float camy, float camz, float rx, float ry,
                                              float rz, float c0x, float c0y, float c0z, int sx, int sxy,
                                              float* __restrict px, float* __restrict py,
                                              float* __restrict pz, int32_t* __restrict idx,
                                              int32_t* __restrict quadrant) {
  for (int j = 0; j < n; ++j) {
    const float x = column_x[j];
    const float dx = rx + c0x * x, dy = ry + c0y * x, dz = rz + c0z * x;
    const float zz = z[j];
    const float ex = camx + dx * zz, ey = camy + dy * zz, ez = camz + dz * zz;
    px[j] = ex;
    py[j] = ey;
    pz[j] = ez;
    const int32_t ix = static_cast<int32_t>(ex), iy = static_cast<int32_t>(ey), iz = static_cast<int32_t>(ez);
    idx[j] = ix + (iy << sx) + (iz << sxy);
    const int32_t hx = ex - static_cast<float>(ix) >= 0.5f, hy = ey - static_cast<float>(iy) >= 0.5f,
                  hz = ez - static_cast<float>(iz) >= 0.5f;
    const float ax = std::abs(dx), ay = std::abs(dy), az = std::abs(dz);
    const int32_t major_x = (ax >= ay) & (ax >= az);
    const int32_t major_z = (1 - major_x) & (az > ay);
    // The two minor axes: (y, z) when x is major, (x, z) when y is, (x, y) when z is. The
    // quadrant is stored as an index: SSE2 has no per-lane variable shift.
    quadrant[j] = (major_x * hy + (1 - major_x) * hx) | ((major_z * hy + (1 - major_z) * hz) << 1);
  }
}

using detail::Walk;

Walk make_walk(float fx, float fy, float fz, int64_t idx, const Eigen::Vector3d& cam,
               const int64_t stride[3]) {
  const float pf[3] = {fx, fy, fz};
  int64_t t_max[3], t_delta[3], step_idx[3];
  int steps = 0;
  for (int a = 0; a < 3; ++a) {
    const int cell = static_cast<int>(pf[a]);
    const double d = cam[a] - pf[a];
    const double frac = pf[a] - cell;
    if (d == 0.0) {
      step_idx[a] = 0;
      t_delta[a] = t_max[a] = kFixedInfinity;
    } else {
      const double inv_d = 1.0 / std::abs(d);
      step_idx[a] = d > 0.0 ? stride[a] : -stride[a];
      t_delta[a] = static_cast<int64_t>(std::min(inv_d * kFixedOne, kFixedInfinityD));
      t_max[a] =
          static_cast<int64_t>(std::min((d > 0.0 ? 1.0 - frac : frac) * inv_d * kFixedOne, kFixedInfinityD));
    }
    // The exact number of voxel boundaries between the end and the camera.
    steps += std::abs(static_cast<int>(std::floor(cam[a])) - cell);
  }
  return {idx,        t_max[0],    t_max[1],    t_max[2],    t_delta[0], t_delta[1],
          t_delta[2], step_idx[0], step_idx[1], step_idx[2], steps};
}

// One step, branch-free: the axis sequence is data-dependent and would mispredict. Three
// independent masks (exactly one set; ties go to x, then y) keep the dependency chain short.
inline void step(Walk& w) {
  const int64_t mx = -static_cast<int64_t>((w.tx <= w.ty) & (w.tx <= w.tz));
  const int64_t my = -static_cast<int64_t>((w.ty < w.tx) & (w.ty <= w.tz));
  const int64_t mz = -static_cast<int64_t>((w.tz < w.tx) & (w.tz < w.ty));
  w.tx += w.dtx & mx;
  w.ty += w.dty & my;
  w.tz += w.dtz & mz;
  w.idx += (w.sx & mx) | (w.sy & my) | (w.sz & mz);
}

// Fast-Planner's walk: stops at the first voxel an earlier ray of the frame walked.
void walk_until_seen(Walk w, uint8_t* marks) {
  for (; w.steps > 0; --w.steps) {
    step(w);
    if (marks[w.idx] & kWalked) break;
    marks[w.idx] |= kWalked;
  }
}

// Full walks, two interleaved: each walk is one long dependency chain, so running two at once
// nearly doubles the throughput (more lanes run out of registers).
void run_walks(const std::vector<Walk>& walks, uint8_t* marks) {
  const size_t n = walks.size();
  if (n == 0) return;
  size_t next = 0;
  Walk a = walks[next++];
  Walk b = next < n ? walks[next++] : Walk{a.idx, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (;;) {
    const int both = std::min(a.steps, b.steps);
    for (int i = 0; i < both; ++i) {
      step(a);
      step(b);
      marks[a.idx] |= kWalked;
      marks[b.idx] |= kWalked;
    }
    a.steps -= both;
    b.steps -= both;
    if (a.steps == 0) {
      if (next == n) break;
      a = walks[next++];
    }
    if (b.steps == 0) {
      if (next == n) {
        std::swap(a, b);
        break;
      }
      b = walks[next++];
    }
  }
  // The one walk left (in b) finishes alone.
  for (; b.steps > 0; --b.steps) {
    step(b);
    marks[b.idx] |= kWalked;
  }
}

}  // namespace

std::string check_frame(const DepthFrame& f) {
  const auto& c = f.camera;
  if (c.width <= 0 || c.height <= 0 || c.width > 16384 || c.height > 16384) {
    return "camera size " + std::to_string(c.width) + "x" + std::to_string(c.height) + " is not plausible";
  }
  if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && c.fx > 0 && c.fy > 0 && std::isfinite(c.cx) &&
        std::isfinite(c.cy))) {
    return "camera intrinsics are not finite and positive";
  }
  if (!(std::isfinite(c.min_range) && std::isfinite(c.max_range) && c.min_range >= 0 &&
        c.max_range > c.min_range)) {
    return "camera range limits are not 0 <= min_range < max_range";
  }
  if (f.depth == nullptr || f.depth_size != static_cast<size_t>(c.width) * static_cast<size_t>(c.height)) {
    return "depth image has " + std::to_string(f.depth_size) + " pixels, expected " +
           std::to_string(static_cast<size_t>(c.width) * static_cast<size_t>(c.height));
  }
  const Eigen::Matrix4d& m = f.T_world_optical.matrix();
  if (!m.allFinite()) return "sensor pose is not finite";
  const Eigen::Matrix3d r = f.T_world_optical.linear();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 ||
      r.determinant() < 0.0) {
    return "sensor orientation is not a rotation";
  }
  if (f.T_world_optical.translation().cwiseAbs().maxCoeff() > kMaxWorldCoordinate) {
    return "sensor position is beyond 1e5 m";
  }
  return {};
}

DepthIntegrator::DepthIntegrator(const IntegrationParams& params) : params_(params) {}

IntegrationReport DepthIntegrator::integrate(const DepthFrame& f, OccupancyMap& map,
                                             std::vector<map::VoxelChange>* changes) {
  IntegrationReport rep;
  rep.error = check_frame(f);
  if (!rep.error.empty()) return rep;
  const runtime::PinholeCamera& cam = f.camera;
  const double z_min = std::max(cam.min_range, params_.min_range);
  const double z_max = std::min(cam.max_range, params_.max_range);
  if (!(z_min < z_max)) {
    rep.error = "camera range [" + std::to_string(cam.min_range) + ", " + std::to_string(cam.max_range) +
                "] does not overlap the mapper's";
    return rep;
  }

  // Everything below works in voxel units relative to the scratch grid's origin voxel, where the
  // integer part of a coordinate is the scratch cell (all coordinates are positive).
  const double inv = map.keys().inv_resolution();
  const Eigen::Matrix3d rs = f.T_world_optical.linear() * inv;
  const Eigen::Vector3d cam_world = f.T_world_optical.translation() * inv;
  Eigen::Vector3d lo = cam_world, hi = cam_world;
  for (double u : {0.0, cam.width - 1.0}) {
    for (double v : {0.0, cam.height - 1.0}) {
      const Eigen::Vector3d c = cam_world + rs * cam.ray(u, v) * z_max;
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  }
  // A very wide field of view (fx tiny against the image) would need a huge scratch grid.
  if ((hi - lo).maxCoeff() > kMaxScratchExtent) {
    rep.error = "view frustum spans more than " + std::to_string(kMaxScratchExtent) +
                " voxels (field of view too wide for this max_range and resolution)";
    return rep;
  }
  rep.accepted = true;
  // Two voxels of margin: a walk can overshoot its segment's box by one voxel on rounding.
  const map::VoxelKey origin{static_cast<int32_t>(std::floor(lo.x())) - 2,
                             static_cast<int32_t>(std::floor(lo.y())) - 2,
                             static_cast<int32_t>(std::floor(lo.z())) - 2};
  const int nx = static_cast<int>(std::floor(hi.x())) + 3 - origin.x;
  const int ny = static_cast<int>(std::floor(hi.y())) + 3 - origin.y;
  const int nz = static_cast<int>(std::floor(hi.z())) + 3 - origin.z;
  // Power-of-two row and plane strides make the cell index a few shifts.
  const int sx = ceil_log2(nx);
  const int sy = ceil_log2(ny);
  const int sxy = sx + sy;
  const size_t cells = static_cast<size_t>(nz) << sxy;
  const size_t words = (cells + 7) / 8;  // the apply pass reads 8 cells at a time
  if (marks_.size() < words * 8) marks_.assign(words * 8, 0);
  uint8_t* const marks = marks_.data();
  const Eigen::Vector3d cam_local = cam_world - Eigen::Vector3d(origin.x, origin.y, origin.z);
  const int64_t stride[3] = {1, int64_t{1} << sx, int64_t{1} << sxy};

  const int step = params_.pixel_step;
  const IntegrationParams::Mode mode = params_.mode;
  const int row_n = (cam.width + step - 1) / step;
  column_x_.resize(row_n);
  for (int j = 0; j < row_n; ++j) column_x_[j] = static_cast<float>((j * step - cam.cx) / cam.fx);
  row_raw_.resize(row_n);
  row_kind_.resize(row_n);
  row_z_.resize(row_n);
  row_p_.resize(3 * static_cast<size_t>(row_n));
  row_idx_.resize(row_n);
  row_quadrant_.resize(row_n);
  float* const px = row_p_.data();
  float* const py = px + row_n;
  float* const pz = py + row_n;
  const float c0x = static_cast<float>(rs(0, 0)), c0y = static_cast<float>(rs(1, 0)),
              c0z = static_cast<float>(rs(2, 0));
  const float camx = static_cast<float>(cam_local.x()), camy = static_cast<float>(cam_local.y()),
              camz = static_cast<float>(cam_local.z());
  int64_t kinds[5] = {0, 0, 0, 0, 0};
  // z-depth, like the range limits: the hold range is a noise bound, and axial noise grows with z.
  const float hold_z = static_cast<float>(map.params().hold_range);

  // ---- pass 1: per image row, the end point of every pixel (vectorised), then marks and walks
  // on the scratch grid ----
  for (int v = 0; v < cam.height; v += step) {
    const Eigen::Vector3d row_dir = rs.col(2) + rs.col(1) * ((v - cam.cy) / cam.fy);
    const uint16_t* depth_row = f.depth + static_cast<size_t>(v) * cam.width;
    const uint16_t* raw_row = depth_row;
    if (step > 1) {
      for (int j = 0; j < row_n; ++j) row_raw_[j] = depth_row[j * step];
      raw_row = row_raw_.data();
    }
    classify_row(raw_row, row_n, static_cast<float>(z_min), static_cast<float>(z_max), row_kind_.data(),
                 row_z_.data(), kinds);
    end_points_row(row_z_.data(), column_x_.data(), row_n, camx, camy, camz, static_cast<float>(row_dir.x()),
                   static_cast<float>(row_dir.y()), static_cast<float>(row_dir.z()), c0x, c0y, c0z, sx, sxy,
                   px, py, pz, row_idx_.data(), row_quadrant_.data());
    for (int j = 0; j < row_n; ++j) {
      const uint8_t kind = row_kind_[j];
      if (kind == kInvalid || kind == kTooNear) continue;
      const bool hit = kind == kHitReturn;
      const uint8_t near = hit && row_z_[j] <= hold_z ? kNearHit : 0;
      const int64_t idx = row_idx_[j];
      const uint8_t m = marks[idx];
      const uint8_t end_bit = static_cast<uint8_t>(kEndQuadrant0 << row_quadrant_[j]);
      const bool covered = mode == IntegrationParams::Mode::kBundled ? (m & end_bit) != 0
                           : mode == IntegrationParams::Mode::kFast  ? (m & kAnyEnd) != 0
                                                                     : false;
      if (covered) {
        // A ray of this frame was walked from here already: this one's way back is covered.
        if (hit) marks[idx] = m | kHit | kWalked | near;
        continue;
      }
      // A max-range end voxel is not itself observed (OctoMap's maxrange convention).
      marks[idx] = m | end_bit | (hit ? (kHit | kWalked | near) : 0);
      ++rep.rays_walked;
      const Walk w = make_walk(px[j], py[j], pz[j], idx, cam_local, stride);
      if (mode == IntegrationParams::Mode::kFast) {
        walk_until_seen(w, marks);  // order matters here: one at a time
      } else {
        walks_.push_back(w);
      }
    }
    run_walks(walks_, marks);
    walks_.clear();
  }
  rep.invalid = kinds[kInvalid];
  rep.hits = kinds[kHitReturn];
  rep.no_return = kinds[kNoReturn];
  rep.beyond_range = kinds[kBeyond];
  rep.too_near = kinds[kTooNear];
  rep.pixels = kinds[kInvalid] + kinds[kHitReturn] + kinds[kNoReturn] + kinds[kBeyond] + kinds[kTooNear];

  // ---- pass 2: one observation per observed voxel, in memory order (consecutive voxels share
  // blocks), clearing the scratch as it goes ----
  const map::VoxelKey bmin = map::block_of(origin);
  const map::VoxelKey bmax = map::block_of(origin + map::VoxelKey{nx - 1, ny - 1, nz - 1});
  const int bnx = bmax.x - bmin.x + 1, bny = bmax.y - bmin.y + 1, bnz = bmax.z - bmin.z + 1;
  block_table_.assign(static_cast<size_t>(bnx) * bny * bnz, nullptr);
  const std::optional<map::KeyBox> bounds = map.bounds();
  const uint32_t mask_x = (1u << sx) - 1, mask_y = (1u << sy) - 1;
  for (size_t w = 0; w < words; ++w) {
    uint64_t bytes;
    std::memcpy(&bytes, marks + 8 * w, 8);
    if (!bytes) continue;
    std::memset(marks + 8 * w, 0, 8);
    do {
      const int b = __builtin_ctzll(bytes) >> 3;
      const uint8_t m = static_cast<uint8_t>(bytes >> (8 * b));
      bytes &= ~(uint64_t{0xFF} << (8 * b));
      if (!(m & kWalked)) continue;  // a max-range end voxel nothing else passed through
      const uint32_t idx = static_cast<uint32_t>(w * 8 + b);
      const map::VoxelKey key{origin.x + static_cast<int32_t>(idx & mask_x),
                              origin.y + static_cast<int32_t>((idx >> sx) & mask_y),
                              origin.z + static_cast<int32_t>(idx >> sxy)};
      ++rep.voxels_updated;
      if (bounds && !bounds->contains(key)) {
        ++rep.out_of_bounds;
        continue;
      }
      const map::VoxelKey bk = map::block_of(key);
      map::VoxelBlock*& block =
          block_table_[(static_cast<size_t>(bk.z - bmin.z) * bny + (bk.y - bmin.y)) * bnx + (bk.x - bmin.x)];
      if (!block) block = &map.block(bk);
      map::VoxelState before, after;
      map.apply(*block, key, map::local_index(key), (m & kHit) != 0, (m & kNearHit) != 0, before, after);
      if (before != after) {
        ++rep.voxels_changed;
        rep.changed_bounds.include(key);
        if (changes) changes->push_back({key, after});
      }
    } while (bytes);
  }
  return rep;
}

}  // namespace semx::mapper
