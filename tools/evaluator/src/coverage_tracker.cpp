#include "semx/evaluator/coverage_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semx::evaluator {

namespace {

Eigen::Vector3i to_eigen(const mapper::VoxelKey& k) { return {k.x, k.y, k.z}; }

}  // namespace

CoverageTracker::CoverageTracker(std::shared_ptr<const simulator::GroundTruth> gt) : gt_(std::move(gt)) {
  if (!gt_) throw std::invalid_argument("CoverageTracker: no ground truth");
  known_.assign(gt_->target().size(), 0);
}

bool CoverageTracker::matches(double resolution) const {
  const double r = gt_->resolution();
  return std::abs(resolution - r) <= 1e-9 * std::max(std::abs(resolution), r);
}

double CoverageTracker::coverage() const {
  const int64_t t = target_count();
  return t > 0 ? static_cast<double>(covered_) / static_cast<double>(t) : 0.0;
}

void CoverageTracker::set(const mapper::VoxelKey& key, mapper::VoxelState state) {
  const Eigen::Vector3i k = to_eigen(key);
  if (!gt_->in_grid(k)) return;
  const size_t i = gt_->index(k);
  if (!gt_->target()[i]) return;
  const uint8_t now = state != mapper::VoxelState::kUnknown;
  if (known_[i] == now) return;
  known_[i] = now;
  covered_ += now ? 1 : -1;
}

bool CoverageTracker::apply(const mapper::MapDelta& delta) {
  if (!matches(delta.resolution)) return false;
  for (const auto& c : delta.changes) set(c.key, c.state);
  return true;
}

bool CoverageTracker::reset(const mapper::StateGrid& grid) {
  clear();
  if (!matches(grid.resolution())) return false;
  // Only blocks with known voxels can cover anything; a map is far smaller than the world's grid
  // early on and about its size at the end, so this is at most one pass over the map.
  grid.for_each_block([&](const mapper::VoxelKey& bk, const mapper::VoxelBlock& b) {
    if (b.known == 0) return;
    for (int i = 0; i < mapper::kBlockVolume; ++i) {
      if (b.state[i] != mapper::VoxelState::kUnknown) set(mapper::voxel_of(bk, i), b.state[i]);
    }
  });
  return true;
}

void CoverageTracker::clear() {
  std::fill(known_.begin(), known_.end(), 0);
  covered_ = 0;
}

bool CoverageTracker::known(const mapper::VoxelKey& key) const {
  const Eigen::Vector3i k = to_eigen(key);
  return gt_->in_grid(k) && known_[gt_->index(k)];
}

int64_t CoverageTracker::count_covered(const simulator::GroundTruth& gt, const mapper::StateGrid& grid) {
  int64_t n = 0;
  auto reader = grid.reader();
  const Eigen::Vector3i& lo = gt.min_key();
  const Eigen::Vector3i& d = gt.dims();
  for (int z = 0; z < d.z(); ++z) {
    for (int y = 0; y < d.y(); ++y) {
      for (int x = 0; x < d.x(); ++x) {
        const Eigen::Vector3i k(lo.x() + x, lo.y() + y, lo.z() + z);
        if (!gt.in_target(k)) continue;
        n += reader.state(mapper::VoxelKey(k.x(), k.y(), k.z())) != mapper::VoxelState::kUnknown;
      }
    }
  }
  return n;
}

}  // namespace semx::evaluator
