#include "semx/fixtures/synthetic_truth.hpp"

#include <vector>

namespace semx::planner {

using map::VoxelKey;

SyntheticTruth::SyntheticTruth(const SyntheticWorld& world) : world_(world) {
  const map::KeyMath km(world.resolution());
  const double r = world.resolution();
  // The interior and the layer of wall around it (SyntheticWorld's own dense box).
  lo_ = km.key(world.interior().min + Eigen::Vector3d::Constant(0.5 * r));
  const VoxelKey hi = km.key(world.interior().max - Eigen::Vector3d::Constant(0.5 * r));
  for (int a = 0; a < 3; ++a) {
    lo_[a] -= 1;
    dims_[a] = hi[a] + 1 - lo_[a] + 1;
  }
  target_.assign(static_cast<size_t>(dims_.x) * dims_.y * dims_.z, 0);
  const VoxelKey start = km.key(world.start());
  if (!inside(start) || world.occupied(start)) return;
  // Flood the free voxels from the start; every occupied face neighbour of one joins T too.
  std::vector<VoxelKey> stack{start};
  target_[index(start)] = 1;
  static const int kFace[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  while (!stack.empty()) {
    const VoxelKey k = stack.back();
    stack.pop_back();
    ++count_;
    for (const auto& f : kFace) {
      const VoxelKey q{k.x + f[0], k.y + f[1], k.z + f[2]};
      if (!inside(q) || target_[index(q)]) continue;
      target_[index(q)] = 1;
      if (world.occupied(q))
        ++count_;
      else
        stack.push_back(q);
    }
  }
}

bool SyntheticTruth::inside(const VoxelKey& k) const {
  return k.x >= lo_.x && k.y >= lo_.y && k.z >= lo_.z && k.x < lo_.x + dims_.x && k.y < lo_.y + dims_.y &&
         k.z < lo_.z + dims_.z;
}

size_t SyntheticTruth::index(const VoxelKey& k) const {
  return static_cast<size_t>(k.x - lo_.x) +
         static_cast<size_t>(dims_.x) * (static_cast<size_t>(k.y - lo_.y) + static_cast<size_t>(dims_.y) * (k.z - lo_.z));
}

bool SyntheticTruth::target(const VoxelKey& k) const { return inside(k) && target_[index(k)]; }

double SyntheticTruth::coverage(const map::StateGrid& known) const {
  if (count_ == 0) return 0.0;
  return static_cast<double>(covered(known)) / static_cast<double>(count_);
}

int64_t SyntheticTruth::covered(const map::StateGrid& known) const {
  int64_t seen = 0;
  map::StateGrid::Reader r = known.reader();
  for (int32_t z = lo_.z; z < lo_.z + dims_.z; ++z)
    for (int32_t y = lo_.y; y < lo_.y + dims_.y; ++y)
      for (int32_t x = lo_.x; x < lo_.x + dims_.x; ++x) {
        const VoxelKey k{x, y, z};
        if (target_[index(k)] && r.state(k) != map::VoxelState::kUnknown) ++seen;
      }
  return seen;
}

}  // namespace semx::planner
