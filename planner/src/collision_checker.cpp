#include "semx/planner/collision_checker.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "semx/mapper/raycast.hpp"

namespace semx::planner {

using mapper::VoxelKey;
using mapper::VoxelState;

CollisionChecker::CollisionChecker(const CollisionConfig& config)
    : config_(config),
      body_half_(0.5 * config.vehicle_size + Eigen::Vector3d::Constant(config.margin)),
      vehicle_half_(0.5 * config.vehicle_size),
      reach_(body_half_.cwiseMax(
          Eigen::Vector3d::Constant(std::max(config.clearance, config.passage_clearance)))) {}

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
    if (std::abs(a) >= mapper::kMaxKeyMagnitude || std::abs(b) >= mapper::kMaxKeyMagnitude) return false;
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
  const VoxelKey bmin = mapper::block_of(kmin), bmax = mapper::block_of(kmax);
  for (int32_t bz = bmin.z; bz <= bmax.z; ++bz) {
    for (int32_t by = bmin.y; by <= bmax.y; ++by) {
      for (int32_t bx = bmin.x; bx <= bmax.x; ++bx) {
        const mapper::VoxelBlock* b = grid_->find_block({bx, by, bz});
        const VoxelKey base{bx * mapper::kBlockSize, by * mapper::kBlockSize, bz * mapper::kBlockSize};
        const int x0 = std::max(kmin.x, base.x) - base.x,
                  x1 = std::min(kmax.x, base.x + mapper::kBlockMask) - base.x;
        const int y0 = std::max(kmin.y, base.y) - base.y,
                  y1 = std::min(kmax.y, base.y + mapper::kBlockMask) - base.y;
        const int z0 = std::max(kmin.z, base.z) - base.z,
                  z1 = std::min(kmax.z, base.z + mapper::kBlockMask) - base.z;
        for (int z = z0; z <= z1; ++z) {
          for (int y = y0; y <= y1; ++y) {
            const VoxelState* row = b ? &b->state[static_cast<size_t>((z << (2 * mapper::kBlockBits)) |
                                                                      (y << mapper::kBlockBits))]
                                      : nullptr;
            for (int x = x0; x <= x1; ++x) {
              const VoxelState s = row ? row[x] : VoxelState::kUnknown;
              if (s == VoxelState::kFree || (s == VoxelState::kUnknown && !unknown_is_occupied)) continue;
              if (blocks(base.x + x, base.y + y, base.z + z)) return false;
            }
          }
        }
      }
    }
  }
  return true;
}

bool CollisionChecker::node_free(const Eigen::Vector3d& p) const {
  return region_free(p, body_half_, config_.clearance, true);
}

bool CollisionChecker::passage_free(const Eigen::Vector3d& p) const {
  return region_free(p, body_half_, config_.passage_clearance, true);
}

bool CollisionChecker::vehicle_free(const Eigen::Vector3d& p) const {
  return region_free(p, vehicle_half_, 0.0, false);
}

bool CollisionChecker::centre(Eigen::Vector3d& p, int iterations, double max_step, bool passage) const {
  if (!grid_ || !p.allFinite()) return false;
  const double res = grid_->resolution(), inv = 1.0 / res;
  const double r = passage ? config_.passage_clearance : config_.clearance;
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
    mapper::StateGrid::Reader reader = grid_->reader();
    for (int32_t z = kmin.z; z <= kmax.z; ++z)
      for (int32_t y = kmin.y; y <= kmax.y; ++y)
        for (int32_t x = kmin.x; x <= kmax.x; ++x) {
          if (reader.state({x, y, z}) == VoxelState::kFree) continue;
          const Eigen::Vector3d lo(x * res, y * res, z * res);
          const Eigen::Vector3d q = p.cwiseMax(lo).cwiseMin(lo + Eigen::Vector3d::Constant(res));
          const Eigen::Vector3d v = p - q;
          const double d = v.norm();
          if (d >= r || d < 1e-9) continue;
          push += (r - d) * v / d;
        }
    const double n = push.norm();
    if (n < 1e-9) return false;  // inside an obstacle or pushed equally from all sides
    p += push * std::min(1.0, max_step / n);
  }
  return ok(p);
}

bool CollisionChecker::centre_line_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        double skip_radius) const {
  if (!grid_) return false;
  mapper::StateGrid::Reader r = grid_->reader();
  const double skip2 = skip_radius * skip_radius;
  const mapper::KeyMath& km = grid_->keys();
  return mapper::traverse_segment(km, a, b, [&](const VoxelKey& k) {
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
  const int n = std::max(1, static_cast<int>(std::ceil(length / config_.edge_step)));
  if (n <= 1) return true;
  // Coarse samples first (every 4th), then the ones between: a blocked edge usually fails early.
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 1; i < n; ++i) {
      if ((i % 4 == 0) != (pass == 0)) continue;
      const double t = static_cast<double>(i) / n;
      const Eigen::Vector3d p = a + t * (b - a);
      const bool near_root = escape_radius > 0 && t * length < escape_radius;
      const bool ok = near_root ? vehicle_free(p) : passage_free(p);
      if (!ok) return false;
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
