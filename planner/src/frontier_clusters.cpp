#include "semx/planner/frontier_clusters.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "semx/map/sort_keys.hpp"
#include "semx/planner/voxel_set.hpp"

namespace semx::planner {

using map::VoxelKey;

FrontierClusters::FrontierClusters(double resolution, int min_voxels, double split_radius)
    : resolution_(resolution), min_voxels_(min_voxels), split_radius_(split_radius) {}

void FrontierClusters::clear() {
  clusters_.clear();
  owner_.clear();
}

const FrontierClusters::Cluster* FrontierClusters::find(int64_t id) const {
  const auto it = clusters_.find(id);
  return it == clusters_.end() ? nullptr : &it->second;
}

int64_t FrontierClusters::owner(const VoxelKey& k) const {
  const auto it = owner_.find(k);
  return it == owner_.end() ? -1 : it->second;
}

Eigen::Vector3d FrontierClusters::centre(const VoxelKey& k) const {
  return {(k.x + 0.5) * resolution_, (k.y + 0.5) * resolution_, (k.z + 0.5) * resolution_};
}

void FrontierClusters::remove(int64_t id, std::vector<VoxelKey>& freed, Changes& out) {
  auto it = clusters_.find(id);
  if (it == clusters_.end()) return;
  for (const VoxelKey& k : it->second.voxels) {
    owner_.erase(k);
    freed.push_back(k);
  }
  clusters_.erase(it);
  out.removed.push_back(id);
}

FrontierClusters::Changes FrontierClusters::update(const std::vector<VoxelKey>& dirty, const Eligible& eligible) {
  Changes out;
  // A cluster that lost a voxel is gone (FUEL's isFrontierChanged): its remaining voxels are
  // grown again, with whatever became eligible next to them.
  std::vector<VoxelKey> seeds;
  for (const VoxelKey& k : dirty) {
    const int64_t id = owner(k);
    if (id >= 0) {
      if (!eligible(k)) remove(id, seeds, out);
    } else {
      seeds.push_back(k);
    }
  }
  grow(std::move(seeds), eligible, out);
  return out;
}

FrontierClusters::Changes FrontierClusters::rebuild(std::vector<VoxelKey> voxels, const Eligible& eligible) {
  Changes out;
  for (const auto& entry : clusters_) out.removed.push_back(entry.first);
  clear();
  grow(std::move(voxels), eligible, out);
  return out;
}

void FrontierClusters::grow(std::vector<VoxelKey> seeds, const Eligible& eligible, Changes& out) {
  map::sort_unique(seeds);
  VoxelSet visited;
  std::vector<VoxelKey> queue;
  for (const VoxelKey& s : seeds) {
    if (!eligible(s) || visited.contains(s) || owner(s) >= 0) continue;
    // Region growing over the 26 neighbours (FUEL's expandFrontier), stopping at voxels that a
    // cluster which did not change still holds.
    queue.assign(1, s);
    visited.insert(s);
    for (size_t head = 0; head < queue.size(); ++head) {
      const VoxelKey c = queue[head];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0 && dz == 0) continue;
            const VoxelKey n{c.x + dx, c.y + dy, c.z + dz};
            // Most neighbours are not frontier voxels: the (block-cached) eligibility first.
            if (!eligible(n) || visited.contains(n) || owner(n) >= 0) continue;
            visited.insert(n);
            queue.push_back(n);
          }
    }
    // Too small a group stays unclustered (and is grown again when a change reaches it).
    if (static_cast<int>(queue.size()) < min_voxels_) continue;
    for (std::vector<VoxelKey>& part : split(queue)) add(std::move(part), out);
  }
  std::sort(out.added.begin(), out.added.end());
}

std::vector<std::vector<VoxelKey>> FrontierClusters::split(std::vector<VoxelKey> voxels) const {
  std::vector<std::vector<VoxelKey>> done;
  std::vector<std::vector<VoxelKey>> todo;
  todo.push_back(std::move(voxels));
  while (!todo.empty()) {
    std::vector<VoxelKey> v = std::move(todo.back());
    todo.pop_back();
    if (v.size() < 2) {
      if (!v.empty()) done.push_back(std::move(v));
      continue;
    }
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const VoxelKey& k : v) mean += centre(k).head<2>();
    mean /= static_cast<double>(v.size());
    bool large = false;
    for (const VoxelKey& k : v) {
      if ((centre(k).head<2>() - mean).norm() > split_radius_) {
        large = true;
        break;
      }
    }
    if (!large) {
      done.push_back(std::move(v));
      continue;
    }
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const VoxelKey& k : v) {
      const Eigen::Vector2d d = centre(k).head<2>() - mean;
      cov += d * d.transpose();
    }
    // The axis of largest spread (eigenvalues ascending): cutting across it halves the extent.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
    const Eigen::Vector2d axis = es.eigenvectors().col(1);
    std::vector<VoxelKey> a, b;
    for (const VoxelKey& k : v) ((centre(k).head<2>() - mean).dot(axis) >= 0 ? a : b).push_back(k);
    if (a.empty() || b.empty()) {  // all on one line through the mean: nothing to cut
      done.push_back(std::move(v));
      continue;
    }
    todo.push_back(std::move(b));
    todo.push_back(std::move(a));
  }
  return done;
}

void FrontierClusters::add(std::vector<VoxelKey> voxels, Changes& out) {
  std::sort(voxels.begin(), voxels.end());
  Cluster c;
  c.id = next_id_++;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const VoxelKey& k : voxels) {
    sum += centre(k);
    c.box.include(k);
    owner_[k] = c.id;
  }
  c.mean = sum / static_cast<double>(voxels.size());
  c.voxels = std::move(voxels);
  out.added.push_back(c.id);
  clusters_.emplace(c.id, std::move(c));
}

}  // namespace semx::planner
