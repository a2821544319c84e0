#include "semx/evaluator/coverage_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semx::evaluator {

namespace {

Eigen::Vector3i to_eigen(const map::VoxelKey& k) { return {k.x, k.y, k.z}; }

}  // namespace

CoverageTracker::CoverageTracker(std::shared_ptr<const simulator::GroundTruth> gt) : gt_(std::move(gt)) {
  if (!gt_) throw std::invalid_argument("CoverageTracker: no ground truth");
  known_.assign(gt_->target().size(), 0);
  object_.assign(gt_->target().size(), 0);
  // A voxel whose cube overlaps the box has its centre less than half a voxel outside it; one
  // that only touches a face (the floor under a table) is exactly half a voxel out: excluded.
  const double half = 0.5 * gt_->resolution() - 1e-6;
  for (const simulator::ObjectInfo& o : gt_->objects()) {
    const Eigen::Vector3d lo = o.center - 0.5 * o.extent - Eigen::Vector3d::Constant(half);
    const Eigen::Vector3d hi = o.center + 0.5 * o.extent + Eigen::Vector3d::Constant(half);
    const Eigen::Vector3i a = gt_->key_of(lo), b = gt_->key_of(hi);
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int x = a.x(); x <= b.x(); ++x) {
          const Eigen::Vector3i k(x, y, z);
          if (!gt_->in_grid(k)) continue;
          const size_t i = gt_->index(k);
          const Eigen::Vector3d c = gt_->center_of(k);
          if (!gt_->target()[i] || gt_->cells()[i] != simulator::GroundTruth::kOccupied || object_[i] ||
              (c.array() < lo.array()).any() || (c.array() > hi.array()).any())
            continue;
          object_[i] = 1;
          ++object_target_;
        }
  }
}

double CoverageTracker::object_coverage() const {
  return object_target_ > 0 ? static_cast<double>(object_covered_) / static_cast<double>(object_target_)
                            : 0.0;
}

bool CoverageTracker::matches(double resolution) const {
  const double r = gt_->resolution();
  return std::abs(resolution - r) <= 1e-9 * std::max(std::abs(resolution), r);
}

double CoverageTracker::coverage() const {
  const int64_t t = target_count();
  return t > 0 ? static_cast<double>(covered_) / static_cast<double>(t) : 0.0;
}

void CoverageTracker::set(const map::VoxelKey& key, map::VoxelState state) {
  const Eigen::Vector3i k = to_eigen(key);
  if (!gt_->in_grid(k)) return;
  const size_t i = gt_->index(k);
  if (!gt_->target()[i]) return;
  const uint8_t now = state != map::VoxelState::kUnknown;
  if (known_[i] == now) return;
  known_[i] = now;
  covered_ += now ? 1 : -1;
  if (object_[i]) object_covered_ += now ? 1 : -1;
}

bool CoverageTracker::apply(const map::MapDelta& delta) {
  if (!matches(delta.resolution)) return false;
  for (const auto& c : delta.changes) set(c.key, c.state);
  return true;
}

bool CoverageTracker::reset(const map::StateGrid& grid) {
  clear();
  if (!matches(grid.resolution())) return false;
  // Only blocks with known voxels can cover anything; a map is far smaller than the world's grid
  // early on and about its size at the end, so this is at most one pass over the map.
  grid.for_each_block([&](const map::VoxelKey& bk, const map::VoxelBlock& b) {
    if (b.known == 0) return;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b.state[i] != map::VoxelState::kUnknown) set(map::voxel_of(bk, i), b.state[i]);
    }
  });
  return true;
}

void CoverageTracker::clear() {
  std::fill(known_.begin(), known_.end(), 0);
  covered_ = 0;
  object_covered_ = 0;
}

bool CoverageTracker::known(const map::VoxelKey& key) const {
  const Eigen::Vector3i k = to_eigen(key);
  return gt_->in_grid(k) && known_[gt_->index(k)];
}

int64_t CoverageTracker::count_covered(const simulator::GroundTruth& gt, const map::StateGrid& grid) {
  int64_t n = 0;
  auto reader = grid.reader();
  const Eigen::Vector3i& lo = gt.min_key();
  const Eigen::Vector3i& d = gt.dims();
  for (int z = 0; z < d.z(); ++z) {
    for (int y = 0; y < d.y(); ++y) {
      for (int x = 0; x < d.x(); ++x) {
        const Eigen::Vector3i k(lo.x() + x, lo.y() + y, lo.z() + z);
        if (!gt.in_target(k)) continue;
        n += reader.state(map::VoxelKey(k.x(), k.y(), k.z())) != map::VoxelState::kUnknown;
      }
    }
  }
  return n;
}

}  // namespace semx::evaluator
