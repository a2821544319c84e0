#include "semx/planner/gain_evaluator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "semx/core/angles.hpp"
#include "semx/map/raycast.hpp"

namespace semx::planner {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// A voxel offset packed into one integer: three fields of kField bits, each biased by kBias, so
// that the node's place plus a ray step's offset is one addition with no carry between fields
// (every field stays in [0, 2^kField)). The fields' low kBlockBits are the voxel's index in its
// block, the rest the block.
constexpr int kField = 21;
constexpr int64_t kBias = int64_t{1} << (kField - 1);
constexpr uint64_t kFieldMask = (uint64_t{1} << kField) - 1;
constexpr uint64_t kLocalBits = static_cast<uint64_t>(map::kBlockMask) |
                                (static_cast<uint64_t>(map::kBlockMask) << kField) |
                                (static_cast<uint64_t>(map::kBlockMask) << (2 * kField));
constexpr uint64_t kBlockSelect = ((uint64_t{1} << (3 * kField)) - 1) & ~kLocalBits;

uint64_t pack(int64_t x, int64_t y, int64_t z) {
  return static_cast<uint64_t>(x + (y << kField) + (z << (2 * kField)));
}
// The voxel's index in its block (map::local_index's layout).
size_t local_of(uint64_t u) {
  return static_cast<size_t>(
      (u & map::kBlockMask) | ((u >> (kField - map::kBlockBits)) & (map::kBlockMask << map::kBlockBits)) |
      ((u >> (2 * kField - 2 * map::kBlockBits)) & (map::kBlockMask << (2 * map::kBlockBits))));
}
int block_field(uint64_t u, int axis) {
  return static_cast<int>(((u >> (axis * kField)) & kFieldMask) >> map::kBlockBits) -
         static_cast<int>(kBias >> map::kBlockBits);
}

// Stands for every block the map has not allocated (all unknown), so a step never tests for null.
const map::VoxelBlock& unknown_block() {
  static const map::VoxelBlock block{};
  return block;
}

// Whether a block's voxel has all six face neighbours in the block, by its index.
const std::array<uint8_t, map::kBlockVolume>& inner_voxel() {
  static const std::array<uint8_t, map::kBlockVolume> table = [] {
    std::array<uint8_t, map::kBlockVolume> t{};
    auto in = [](int v) { return v > 0 && v < map::kBlockMask; };
    for (int i = 0; i < map::kBlockVolume; ++i) {
      t[static_cast<size_t>(i)] = in(i & map::kBlockMask) && in((i >> map::kBlockBits) & map::kBlockMask) &&
                                  in(i >> (2 * map::kBlockBits));
    }
    return t;
  }();
  return table;
}

// An unknown voxel's kind from its six face neighbours' states: the states' bits say free (1) and
// occupied (2), so their OR says whether any neighbour is free and any occupied.
static_assert(static_cast<int>(map::VoxelState::kFree) == 1 &&
              static_cast<int>(map::VoxelState::kOccupied) == 2);
GainVoxel kind_of(const map::VoxelState (&n)[6]) {
  constexpr GainVoxel kinds[4] = {GainVoxel::kUnknown, GainVoxel::kFrontier, GainVoxel::kUnknown,
                                  GainVoxel::kSurface};
  const unsigned any = static_cast<unsigned>(n[0]) | static_cast<unsigned>(n[1]) |
                       static_cast<unsigned>(n[2]) | static_cast<unsigned>(n[3]) |
                       static_cast<unsigned>(n[4]) | static_cast<unsigned>(n[5]);
  return kinds[any & 3];
}

// Squares of the points of [lo, hi].
std::pair<double, double> square_range(double lo, double hi) {
  const double a = lo * lo, b = hi * hi;
  if (lo <= 0.0 && hi >= 0.0) return {0.0, std::max(a, b)};
  return {std::min(a, b), std::max(a, b)};
}
}  // namespace

using map::VoxelKey;
using map::VoxelState;

int64_t NodeGain::total_voxels() const {
  int64_t n = 0;
  for (const auto& c : bin_count) n += c[0] + c[1] + c[2];
  return n;
}

GainEvaluator::GainEvaluator(const GainConfig& config) : config_(config) {
  const int bins = config_.yaw_bins;
  window_ =
      std::clamp(static_cast<int>(std::lround(config_.horizontal_fov() / (2.0 * core::kPi / bins))), 1, bins);
  const double half_vfov = 0.5 * config_.vertical_fov();
  // The image's vertical extent shrinks off-axis: at horizontal angle a from the optical axis a
  // pixel row sees elevations up to atan(tan(vfov/2) cos a). Counting only what every column of
  // the window sees (a = hfov/2) keeps the model conservative: a voxel counted for a window is
  // seen when the camera looks along that window's centre (up to occlusion).
  tan_half_vfov_ =
      std::tan(half_vfov) * std::cos(std::min(0.5 * config_.horizontal_fov(), 0.5 * core::kPi - 1e-6));
  const int na = config_.rays_azimuth, ne = config_.rays_elevation;
  directions_.reserve(static_cast<size_t>(na) * ne);
  for (int e = 0; e < ne; ++e) {
    const double max_el = std::atan(tan_half_vfov_);
    const double el = ne == 1 ? 0.0 : -max_el + 2.0 * max_el * e / (ne - 1);
    for (int a = 0; a < na; ++a) {
      const double az = -core::kPi + (a + 0.5) * 2.0 * core::kPi / na;
      directions_.emplace_back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      direction_bin_.push_back(bin_of(az));
    }
  }
  for (int b = 0; b < bins; ++b) {
    const double a = -core::kPi + b * bin_width();
    bin_boundary_.emplace_back(std::cos(a), std::sin(a));
  }
}

int GainEvaluator::bin_near(const Eigen::Vector3d& c, int b) const {
  // Bin b holds the azimuths [u_b, u_b+1): c is at or after boundary b and before boundary b + 1
  // (two cross products; bins are narrower than pi). Azimuth exactly pi is the last bin, as in
  // bin_of(atan2).
  const int bins = config_.yaw_bins;
  if (bins == 1) return 0;
  if (c.y() == 0.0 && c.x() < 0.0) return bins - 1;
  auto after = [&](int boundary) {
    const Eigen::Vector2d& u = bin_boundary_[static_cast<size_t>(boundary)];
    return u.x() * c.y() - u.y() * c.x() >= 0.0;
  };
  for (int guard = 0; guard < bins; ++guard) {
    const int next = b + 1 == bins ? 0 : b + 1;
    if (!after(b)) {
      b = b == 0 ? bins - 1 : b - 1;
    } else if (after(next)) {
      b = next;
    } else {
      return b;
    }
  }
  return bin_of(std::atan2(c.y(), c.x()));
}

double GainEvaluator::bin_width() const { return 2.0 * core::kPi / config_.yaw_bins; }

double GainEvaluator::window_yaw(int j) const {
  return core::wrap_angle(-core::kPi + (j + 0.5 * window_) * bin_width());
}

int GainEvaluator::bin_of(double azimuth) const {
  const int b = static_cast<int>(std::floor((azimuth + core::kPi) / bin_width()));
  return std::clamp(b, 0, config_.yaw_bins - 1);
}

bool GainEvaluator::classify(map::StateGrid::Reader& r, const VoxelKey& k, GainVoxel& kind) {
  if (r.state(k) != VoxelState::kUnknown) return false;
  VoxelState n[6];
  for (size_t i = 0; i < 6; ++i) n[i] = r.state(k + map::kFaceNeighbours[i]);
  kind = kind_of(n);
  return true;
}

bool GainEvaluator::in_sector(const Eigen::Vector3d& c) const {
  const double r2 = c.squaredNorm();
  if (r2 < config_.min_range * config_.min_range || r2 > config_.max_range * config_.max_range) return false;
  // |z| <= tan(vfov/2) * horizontal distance, squared.
  const double h2 = c.x() * c.x() + c.y() * c.y();
  return c.z() * c.z() <= tan_half_vfov_ * tan_half_vfov_ * h2 * (1.0 + 1e-12);
}

uint8_t GainEvaluator::sector_of_cube(const Eigen::Vector3d& o, double h) const {
  // in_sector() on every point of the cube, from the ranges of its squared terms. The margin eps
  // (m², far above the rounding of c) leaves to the exact test every cube that comes near a
  // boundary, so the table never decides a voxel differently from in_sector(c).
  constexpr double eps = 1e-9;
  const auto x = square_range(o.x() - h, o.x() + h), y = square_range(o.y() - h, o.y() + h),
             z = square_range(o.z() - h, o.z() + h);
  const double r2_lo = x.first + y.first + z.first, r2_hi = x.second + y.second + z.second;
  const double h2_lo = x.first + y.first, h2_hi = x.second + y.second;
  const double min2 = config_.min_range * config_.min_range, max2 = config_.max_range * config_.max_range;
  const double t2 = tan_half_vfov_ * tan_half_vfov_;
  if (r2_hi < min2 - eps || r2_lo > max2 + eps || z.first > t2 * h2_hi * (1.0 + 1e-12) + eps) return kOut;
  if (r2_lo > min2 + eps && r2_hi < max2 - eps && z.second < t2 * h2_lo - eps) return kIn;
  return kTest;
}

uint16_t GainEvaluator::bin_of_cube(const Eigen::Vector3d& o, double h) const {
  const int bins = config_.yaw_bins;
  if (bins == 1) return 0;
  // Bin b is where the cross product with its start boundary is >= 0 and with the next one's < 0
  // (bin_near()); both are linear, so the square's corners bound them.
  constexpr double eps = 1e-9;
  const int b = bin_of(std::atan2(o.y(), o.x()));
  const Eigen::Vector2d& u0 = bin_boundary_[static_cast<size_t>(b)];
  const Eigen::Vector2d& u1 = bin_boundary_[static_cast<size_t>(b + 1 == bins ? 0 : b + 1)];
  for (const double cx : {o.x() - h, o.x() + h}) {
    for (const double cy : {o.y() - h, o.y() + h}) {
      if (!(u0.x() * cy - u0.y() * cx > eps) || !(u1.x() * cy - u1.y() * cx < -eps)) return kNoBin;
    }
  }
  return static_cast<uint16_t>(b);
}

void GainEvaluator::add(NodeGain& g, int b, GainVoxel kind) const {
  const int i = static_cast<int>(kind);
  const double w[3] = {config_.weight_unknown, config_.weight_frontier, config_.weight_surface};
  g.bin_gain[static_cast<size_t>(b)] += static_cast<float>(w[i]);
  ++g.bin_count[static_cast<size_t>(b)][static_cast<size_t>(i)];
}

void GainEvaluator::finish(NodeGain& g) const {
  const int bins = config_.yaw_bins;
  std::vector<double> sums(static_cast<size_t>(bins), 0.0);
  double best = -1.0;
  for (int j = 0; j < bins; ++j) {
    double s = 0.0;
    for (int w = 0; w < window_; ++w) s += g.bin_gain[static_cast<size_t>((j + w) % bins)];
    sums[static_cast<size_t>(j)] = s;
    best = std::max(best, s);
  }
  // Several windows often tie (a small cluster fits in many): take the middle of the first run
  // of tied windows (circularly), the one that centres the cluster.
  auto tied = [&](int j) { return sums[static_cast<size_t>(((j % bins) + bins) % bins)] >= best - 1e-9; };
  int start = 0;
  while (start < bins && !tied(start)) ++start;
  if (start == 0 && tied(bins - 1)) {
    while (start > -bins + 1 && tied(start - 1)) --start;  // the run wraps around bin 0
  }
  int length = 0;
  while (length < bins && tied(start + length)) ++length;
  const int best_j = (((start + length / 2) % bins) + bins) % bins;
  g.best_window = best_j;
  g.gain = std::max(0.0, best);
  g.yaw = window_yaw(best_j);
  g.counts = {0, 0, 0};
  for (int w = 0; w < window_; ++w) {
    const auto& c = g.bin_count[static_cast<size_t>((best_j + w) % bins)];
    for (int i = 0; i < 3; ++i) g.counts[static_cast<size_t>(i)] += c[static_cast<size_t>(i)];
  }
  g.valid = true;
}

int GainEvaluator::window_of(double yaw) const {
  // Window j is centred at -pi + (j + W/2) * width.
  const int bins = config_.yaw_bins;
  const int j =
      static_cast<int>(std::lround((core::wrap_angle(yaw) + core::kPi) / bin_width() - 0.5 * window_));
  return ((j % bins) + bins) % bins;
}

double GainEvaluator::gain_at_yaw(const NodeGain& g, double yaw) const {
  if (!g.valid) return 0.0;
  const int bins = config_.yaw_bins;
  const int j = window_of(yaw);
  double s = 0.0;
  for (int w = 0; w < window_; ++w) s += g.bin_gain[static_cast<size_t>((((j + w) % bins) + bins) % bins)];
  return s;
}

double GainEvaluator::goal_gain(const NodeGain& g, double from_yaw, double yaw) const {
  return config_.sweep ? sweep_gain(g, from_yaw, window_of(yaw)) : gain_at_yaw(g, yaw);
}

void GainEvaluator::sweep_gains(const NodeGain& g, double from_yaw, std::vector<double>& out) const {
  const int bins = config_.yaw_bins;
  out.assign(static_cast<size_t>(bins), 0.0);
  if (!g.valid) return;
  // prefix[k] = bins [0, k) over two laps, so any circular run is one difference.
  std::vector<double>& prefix = sweep_prefix_;
  prefix.assign(static_cast<size_t>(2 * bins + 1), 0.0);
  for (int k = 0; k < 2 * bins; ++k)
    prefix[static_cast<size_t>(k + 1)] =
        prefix[static_cast<size_t>(k)] + g.bin_gain[static_cast<size_t>(k % bins)];
  const int from = window_of(from_yaw);
  for (int j = 0; j < bins; ++j) {
    // Counter-clockwise (increasing bins) from `from` to j, or clockwise from j to `from`; at a
    // half turn either way, as the path's yaws take it (core::wrap_angle).
    const bool ccw = core::wrap_angle(window_yaw(j) - window_yaw(from)) >= 0.0;
    const int start = ccw ? from : j;
    const int span = std::min(bins, ((ccw ? j - from : from - j) % bins + bins) % bins + window_);
    out[static_cast<size_t>(j)] =
        prefix[static_cast<size_t>(start + span)] - prefix[static_cast<size_t>(start)];
  }
}

double GainEvaluator::sweep_gain(const NodeGain& g, double from_yaw, int to_window) const {
  std::vector<double> all;
  sweep_gains(g, from_yaw, all);
  const int bins = config_.yaw_bins;
  return all.empty() ? 0.0 : all[static_cast<size_t>(((to_window % bins) + bins) % bins)];
}

void GainEvaluator::prepare(double res) {
  seen_res_ = res;
  const double reach = config_.max_range + res;
  // Every ray is walked once from the centre of the node's voxel (3-D DDA, Amanatides & Woo; on
  // ties z, then y) and its voxels kept as offsets: an evaluation then reads states along the
  // lists. The walk itself cost ~11 ns a voxel (a data-dependent three-way branch per step);
  // reading the list costs a fraction of that (semx-perf-planner --kernels).
  ray_steps_.clear();
  ray_begin_.assign(1, 0);
  for (const Eigen::Vector3d& d : directions_) {
    int k[3] = {0, 0, 0}, st[3] = {0, 0, 0};
    double tm[3], td[3];
    for (int a = 0; a < 3; ++a) {
      tm[a] = td[a] = kInf;
      if (d[a] > 0) {
        st[a] = 1;
        tm[a] = 0.5 * res / d[a];
        td[a] = res / d[a];
      } else if (d[a] < 0) {
        st[a] = -1;
        tm[a] = -0.5 * res / d[a];
        td[a] = -res / d[a];
      }
    }
    for (;;) {
      ray_steps_.push_back(
          {static_cast<int16_t>(k[0]), static_cast<int16_t>(k[1]), static_cast<int16_t>(k[2]), 0});
      const int a = tm[0] < tm[1] ? (tm[0] < tm[2] ? 0 : 2) : (tm[1] < tm[2] ? 1 : 2);
      if (tm[a] > reach) break;
      k[a] += st[a];
      tm[a] += td[a];
    }
    ray_begin_.push_back(static_cast<uint32_t>(ray_steps_.size()));
  }
  // The bitset spans exactly the offsets the rays reach.
  hx_ = hz_ = 0;
  for (const RayStep& r : ray_steps_) {
    hx_ = std::max({hx_, std::abs(static_cast<int>(r.dx)), std::abs(static_cast<int>(r.dy))});
    hz_ = std::max(hz_, std::abs(static_cast<int>(r.dz)));
  }
  // The packed fields hold the node's place in its block plus any offset without a carry.
  if (hx_ + map::kBlockSize >= kBias || hz_ + map::kBlockSize >= kBias)
    throw std::invalid_argument("gain: max_range / resolution too large for the ray tables");
  const size_t bits = static_cast<size_t>(2 * hx_ + 1) * (2 * hx_ + 1) * (2 * hz_ + 1);
  const int nx = 2 * hx_ + 1;
  // A node lies anywhere in its voxel: its offset to the voxel's centre is within half a voxel.
  const double h = 0.5 * res + 1e-9;
  step_packed_.clear();
  step_info_.clear();
  step_packed_.reserve(ray_steps_.size());
  step_info_.reserve(ray_steps_.size());
  for (const RayStep& r : ray_steps_) {
    step_packed_.push_back(pack(r.dx, r.dy, r.dz));
    const Eigen::Vector3d o(r.dx * res, r.dy * res, r.dz * res);
    StepInfo info;
    info.bit = static_cast<uint32_t>((r.dx + hx_) + nx * ((r.dy + hx_) + nx * (r.dz + hz_)));
    info.sector = sector_of_cube(o, h);
    info.bin = bin_of_cube(o, h);
    info.pad = 0;
    step_info_.push_back(info);
  }
  seen_.assign((bits + 63) / 64, 0);
  surface_.assign(seen_.size(), 0);
  // Blocks an offset or one of its face neighbours can fall in, relative to the node's block,
  // whatever the node's place in it.
  block_lo_ = (-hx_ - 1) >> map::kBlockBits;
  block_n_ = ((map::kBlockMask + hx_ + 1) >> map::kBlockBits) - block_lo_ + 1;
  block_lo_z_ = (-hz_ - 1) >> map::kBlockBits;
  const int nz = ((map::kBlockMask + hz_ + 1) >> map::kBlockBits) - block_lo_z_ + 1;
  block_ptr_.assign(static_cast<size_t>(block_n_) * block_n_ * nz, nullptr);
  block_stamp_.assign(block_ptr_.size(), 0u);
  ignored_ptr_.assign(block_ptr_.size(), nullptr);
  stamp_ = 0;
}

NodeGain GainEvaluator::evaluate(const map::StateGrid& grid, const Eigen::Vector3d& p, GainStats* stats) {
  return evaluate(grid, p, 0.0, nullptr, stats);
}

NodeGain GainEvaluator::evaluate(const map::StateGrid& grid, const Eigen::Vector3d& p, double yaw,
                                 std::vector<VoxelKey>* counted, GainStats* stats) {
  const int bins = config_.yaw_bins;
  const int first = counted ? window_of(yaw) : 0;
  auto in_window = [&](int b) { return ((b - first) % bins + bins) % bins < window_; };
  NodeGain g;
  g.bin_gain.assign(static_cast<size_t>(config_.yaw_bins), 0.0f);
  g.bin_count.assign(static_cast<size_t>(config_.yaw_bins), {0, 0, 0});
  const map::KeyMath& km = grid.keys();
  VoxelKey origin;
  if (!p.allFinite() || !km.key(p, origin)) {
    finish(g);
    return g;
  }
  const double res = grid.resolution();
  if (seen_res_ != res || seen_.empty()) {
    prepare(res);
  } else {
    std::memset(seen_.data(), 0, seen_.size() * sizeof(uint64_t));
    if (config_.surface_occludes) std::memset(surface_.data(), 0, surface_.size() * sizeof(uint64_t));
  }
  const bool occlude = config_.surface_occludes;
  const VoxelKey origin_block = map::block_of(origin);
  const int ox = origin.x & map::kBlockMask, oy = origin.y & map::kBlockMask, oz = origin.z & map::kBlockMask;
  const map::VoxelBlock* origin_b = grid.find_block(origin_block);
  const bool ignore = ignored_ && !ignored_->empty();
  const VoxelSet::Mask* origin_ignored = ignore ? ignored_->block_mask(origin_block) : nullptr;
  if (++stamp_ == 0) {  // wrapped: forget every stamp
    std::fill(block_stamp_.begin(), block_stamp_.end(), 0u);
    stamp_ = 1;
  }
  // The block at (bx, by, bz) blocks from the node's, looked up once per evaluation.
  auto slot_of = [&](int bx, int by, int bz) {
    const size_t slot =
        static_cast<size_t>((bx - block_lo_) + block_n_ * ((by - block_lo_) + block_n_ * (bz - block_lo_z_)));
    if (block_stamp_[slot] != stamp_) {
      block_stamp_[slot] = stamp_;
      const VoxelKey block{origin_block.x + bx, origin_block.y + by, origin_block.z + bz};
      block_ptr_[slot] = grid.find_block(block);
      ignored_ptr_[slot] = ignore ? ignored_->block_mask(block) : nullptr;
    }
    return slot;
  };
  // A voxel's state by its offset from the node's block origin: a voxel on a block's face has
  // neighbours in the next block, and the cursor of StateGrid::Reader, which holds one block,
  // went back to the hash map for them once or twice per voxel.
  auto state_at = [&](int ux, int uy, int uz) {
    const map::VoxelBlock* nb =
        block_ptr_[slot_of(ux >> map::kBlockBits, uy >> map::kBlockBits, uz >> map::kBlockBits)];
    if (!nb) return VoxelState::kUnknown;
    const int lx = ux & map::kBlockMask, ly = uy & map::kBlockMask, lz = uz & map::kBlockMask;
    return nb->state[static_cast<size_t>(lx | (ly << map::kBlockBits) | (lz << (2 * map::kBlockBits)))];
  };
  // Of a voxel on its block's faces (b its block, li its index there): the neighbours inside the
  // block are read from it, only the others by their block (a slot lookup each, which made this a
  // tenth of an evaluation's instructions when all six went that way).
  auto border_kind = [&](int ux, int uy, int uz, const map::VoxelBlock* b, size_t li) {
    const int lx = ux & map::kBlockMask, ly = uy & map::kBlockMask, lz = uz & map::kBlockMask;
    constexpr size_t dy1 = map::kBlockSize, dz1 = map::kBlockSize * map::kBlockSize;
    auto own = [&](size_t j) { return b ? b->state[j] : VoxelState::kUnknown; };
    const VoxelState n[6] = {lx > 0 ? own(li - 1) : state_at(ux - 1, uy, uz),
                             lx < map::kBlockMask ? own(li + 1) : state_at(ux + 1, uy, uz),
                             ly > 0 ? own(li - dy1) : state_at(ux, uy - 1, uz),
                             ly < map::kBlockMask ? own(li + dy1) : state_at(ux, uy + 1, uz),
                             lz > 0 ? own(li - dz1) : state_at(ux, uy, uz - 1),
                             lz < map::kBlockMask ? own(li + dz1) : state_at(ux, uy, uz + 1)};
    return kind_of(n);
  };
  int64_t steps = 0;
  const map::VoxelBlock* const none = &unknown_block();
  const uint8_t* const inner = inner_voxel().data();
  const uint64_t base = pack(kBias + ox, kBias + oy, kBias + oz);
  const uint64_t* const packed = step_packed_.data();
  const StepInfo* const info = step_info_.data();
  // The gain's ray casting, the planner's hottest loop: a step through a free voxel is one
  // addition, a mask and compare for the block, the index in the block and one load.
  for (size_t ray = 0; ray < directions_.size(); ++ray) {
    const int ray_bin = direction_bin_[ray];
    // The block is looked up only when the step leaves the one looked up last.
    uint64_t cur = base & kBlockSelect;
    const map::VoxelBlock* b = origin_b ? origin_b : none;
    const VoxelSet::Mask* ignored_mask = origin_ignored;
    const size_t first_step = ray_begin_[ray], last_step = ray_begin_[ray + 1];
    size_t i = first_step;
    for (; i != last_step; ++i) {
      const uint64_t u = base + packed[i];
      if ((u & kBlockSelect) != cur) {
        cur = u & kBlockSelect;
        // Rays cross ~4 blocks each and share them: each block is looked up once per evaluation.
        const size_t slot = slot_of(block_field(u, 0), block_field(u, 1), block_field(u, 2));
        b = block_ptr_[slot] ? block_ptr_[slot] : none;
        ignored_mask = ignored_ptr_[slot];
      }
      const size_t li = local_of(u);
      // Free first: most steps of a mapped world are, and then they take one compare.
      const VoxelState s = b->state[li];
      if (s == VoxelState::kFree) continue;
      if (s == VoxelState::kOccupied) break;
      const StepInfo& in = info[i];
      uint64_t& word = seen_[in.bit >> 6];
      const uint64_t mask = uint64_t{1} << (in.bit & 63);
      if (word & mask) {
        if (occlude && (surface_[in.bit >> 6] & mask)) break;
        continue;
      }
      word |= mask;
      const RayStep& d = ray_steps_[i];
      // Only a voxel on its block's faces needs its place (its neighbours in other blocks).
      auto border = [&]() { return border_kind(ox + d.dx, oy + d.dy, oz + d.dz, b, li); };
      GainVoxel kind = GainVoxel::kUnknown;
      bool known_kind = false;
      if (inner[li]) {
        // All six neighbours are in this block: read them directly (an unallocated block is all
        // unknown, so its inner voxels are "normal").
        known_kind = true;
        constexpr size_t dy1 = map::kBlockSize, dz1 = map::kBlockSize * map::kBlockSize;
        const VoxelState n[6] = {b->state[li - 1],   b->state[li + 1],   b->state[li - dy1],
                                 b->state[li + dy1], b->state[li - dz1], b->state[li + dz1]};
        kind = kind_of(n);
      }
      if (occlude) {
        // The kind decides whether the ray goes on, inside the sector or not.
        if (!known_kind) {
          kind = border();
          known_kind = true;
        }
        if (kind == GainVoxel::kSurface) surface_[in.bit >> 6] |= mask;
      }
      // The sector test and the bin from the step's table where they hold wherever the node is
      // in its voxel, else from the voxel's centre as seen from the node.
      auto key = [&]() { return VoxelKey{origin.x + d.dx, origin.y + d.dy, origin.z + d.dz}; };
      Eigen::Vector3d c;
      bool have_c = false;
      auto centre = [&]() -> const Eigen::Vector3d& {
        if (!have_c) {
          c = km.center(key()) - p;
          have_c = true;
        }
        return c;
      };
      const bool inside = in.sector == kIn || (in.sector == kTest && in_sector(centre()));
      if (inside && !(ignored_mask && VoxelSet::test(*ignored_mask, static_cast<int>(li)))) {
        if (!known_kind) kind = border();
        const int bin = in.bin != kNoBin ? in.bin : bin_near(centre(), ray_bin);
        add(g, bin, kind);
        if (counted && in_window(bin)) counted->push_back(key());
      }
      if (occlude && kind == GainVoxel::kSurface) break;
    }
    // A ray that stopped at step i visited it too.
    steps += static_cast<int64_t>(std::min(i + 1, last_step) - first_step);
  }
  if (stats) {
    ++stats->evaluations;
    stats->rays += static_cast<int64_t>(directions_.size());
    stats->steps += steps;
  }
  finish(g);
  return g;
}

NodeGain GainEvaluator::evaluate_exact(const map::StateGrid& grid, const Eigen::Vector3d& p) const {
  NodeGain g;
  g.bin_gain.assign(static_cast<size_t>(config_.yaw_bins), 0.0f);
  g.bin_count.assign(static_cast<size_t>(config_.yaw_bins), {0, 0, 0});
  const map::KeyMath& km = grid.keys();
  VoxelKey origin;
  if (!p.allFinite() || !km.key(p, origin)) {
    finish(g);
    return g;
  }
  const int h = static_cast<int>(std::ceil(config_.max_range / grid.resolution())) + 1;
  map::StateGrid::Reader r = grid.reader();
  for (int z = -h; z <= h; ++z) {
    for (int y = -h; y <= h; ++y) {
      for (int x = -h; x <= h; ++x) {
        const VoxelKey k{origin.x + x, origin.y + y, origin.z + z};
        const Eigen::Vector3d c = km.center(k) - p;
        if (!in_sector(c)) continue;
        GainVoxel kind;
        if (ignored_ && ignored_->contains(k)) continue;
        if (!classify(r, k, kind)) continue;
        if (!grid.is_visible(p, km.center(k), false)) continue;
        add(g, bin_of(std::atan2(c.y(), c.x())), kind);
      }
    }
  }
  finish(g);
  return g;
}

}  // namespace semx::planner
