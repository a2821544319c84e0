#include "semx/simulator/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "semx/simulator/collision.hpp"

namespace semx::simulator {
namespace {
// Bounds lying on the voxel grid must not gain a sliver layer from rounding.
constexpr double kGridEps = 1e-6;
const int kNeighbours[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
}  // namespace

std::vector<ObjectInfo> list_objects(const World& world) {
  std::map<uint16_t, std::pair<ObjectInfo, Aabb>> by_id;
  for (const auto& s : world.solids) {
    if (runtime::class_info(s.cls).structural) continue;
    auto it = by_id.find(s.instance);
    if (it == by_id.end()) {
      ObjectInfo info;
      info.cls = s.cls;
      info.instance = s.instance;
      by_id.emplace(s.instance, std::make_pair(info, s.bounds()));
      it = by_id.find(s.instance);
    } else {
      it->second.second.extend(s.bounds());
    }
    ++it->second.first.solids;
  }
  std::vector<ObjectInfo> out;
  for (auto& [id, entry] : by_id) {
    entry.first.center = entry.second.center();
    entry.first.extent = entry.second.size();
    out.push_back(entry.first);
  }
  return out;
}

GroundTruth::GroundTruth(const World& world, double resolution) : res_(resolution) {
  for (int a = 0; a < 3; ++a) {
    min_key_[a] = static_cast<int>(std::floor(world.bounds.min[a] / res_ + kGridEps));
    dims_[a] = static_cast<int>(std::ceil(world.bounds.max[a] / res_ - kGridEps)) - min_key_[a];
  }
  const size_t n = static_cast<size_t>(dims_.x()) * dims_.y() * dims_.z();
  cells_.assign(n, kFree);
  target_.assign(n, 0);

  for (const auto& s : world.solids) {
    const Aabb b = s.bounds();
    Eigen::Vector3i lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(min_key_[a], static_cast<int>(std::floor(b.min[a] / res_)));
      hi[a] = std::min(min_key_[a] + dims_[a] - 1, static_cast<int>(std::floor(b.max[a] / res_)));
    }
    for (int k = lo.z(); k <= hi.z(); ++k) {
      for (int j = lo.y(); j <= hi.y(); ++j) {
        for (int i = lo.x(); i <= hi.x(); ++i) {
          const Eigen::Vector3i key(i, j, k);
          uint8_t& c = cells_[index(key)];
          if (c == kOccupied) continue;
          const Aabb cube{key.cast<double>() * res_, (key.cast<double>() + Eigen::Vector3d::Ones()) * res_};
          if (overlaps(cube, s)) c = kOccupied;
        }
      }
    }
  }
  for (uint8_t c : cells_) occupied_ += c == kOccupied;

  // Flood the free space from the start through voxels whose centres are inside the bounds.
  const Eigen::Vector3i start = key_of(world.start.position);
  std::vector<Eigen::Vector3i> queue;
  if (in_grid(start) && cells_[index(start)] == kFree) {
    cells_[index(start)] = kReachable;
    queue.push_back(start);
  }
  for (size_t q = 0; q < queue.size(); ++q) {
    const Eigen::Vector3i key = queue[q];
    for (const auto& d : kNeighbours) {
      const Eigen::Vector3i nb = key + Eigen::Vector3i(d[0], d[1], d[2]);
      if (!in_grid(nb)) continue;
      uint8_t& c = cells_[index(nb)];
      if (c != kFree || !world.bounds.contains(center_of(nb))) continue;
      c = kReachable;
      queue.push_back(nb);
    }
  }
  reachable_ = queue.size();

  std::vector<uint8_t> column(static_cast<size_t>(dims_.x()) * dims_.y(), 0);
  for (const auto& key : queue) {
    target_[index(key)] = 1;
    column[static_cast<size_t>(key.y() - min_key_.y()) * dims_.x() + (key.x() - min_key_.x())] = 1;
    for (const auto& d : kNeighbours) {
      const Eigen::Vector3i nb = key + Eigen::Vector3i(d[0], d[1], d[2]);
      if (!in_grid(nb)) continue;
      const size_t i = index(nb);
      if (cells_[i] == kOccupied && !target_[i]) {
        target_[i] = 1;
        ++occupied_target_;
      }
    }
  }
  area_ = static_cast<double>(std::count(column.begin(), column.end(), 1)) * res_ * res_;
  objects_ = list_objects(world);
}

Eigen::Vector3i GroundTruth::key_of(const Eigen::Vector3d& p) const {
  return {static_cast<int>(std::floor(p.x() / res_)), static_cast<int>(std::floor(p.y() / res_)),
          static_cast<int>(std::floor(p.z() / res_))};
}

Eigen::Vector3d GroundTruth::center_of(const Eigen::Vector3i& key) const {
  return (key.cast<double>() + Eigen::Vector3d::Constant(0.5)) * res_;
}

bool GroundTruth::in_grid(const Eigen::Vector3i& key) const {
  const Eigen::Vector3i r = key - min_key_;
  return (r.array() >= 0).all() && (r.array() < dims_.array()).all();
}

size_t GroundTruth::index(const Eigen::Vector3i& key) const {
  const Eigen::Vector3i r = key - min_key_;
  return (static_cast<size_t>(r.z()) * dims_.y() + r.y()) * dims_.x() + r.x();
}

GroundTruth::Cell GroundTruth::cell(const Eigen::Vector3i& key) const {
  return in_grid(key) ? static_cast<Cell>(cells_[index(key)]) : kFree;
}

bool GroundTruth::in_target(const Eigen::Vector3i& key) const { return in_grid(key) && target_[index(key)]; }

VehicleReachability::VehicleReachability(const GroundTruth& gt, const Eigen::Vector3d& start,
                                         const Eigen::Vector3d& body_size)
    : gt_(gt) {
  const Eigen::Vector3i dims = gt.dims();
  const size_t n = gt.cells().size();
  // A body centred on a voxel centre overlaps the voxel k steps away iff |k| res < h + res/2.
  Eigen::Vector3i reach;
  for (int a = 0; a < 3; ++a) {
    reach[a] = static_cast<int>(std::ceil(0.5 * body_size[a] / gt.resolution() + 0.5 - 1e-9)) - 1;
  }
  // Separable dilation of the occupancy by the body's voxel footprint; outside the grid is
  // blocked.
  std::vector<uint8_t> blocked(n), tmp(n);
  for (size_t i = 0; i < n; ++i) blocked[i] = gt.cells()[i] == GroundTruth::kOccupied;
  const size_t stride[3] = {1, static_cast<size_t>(dims.x()), static_cast<size_t>(dims.x()) * dims.y()};
  for (int a = 0; a < 3; ++a) {
    tmp = blocked;
    for (int k = 0; k < dims.z(); ++k) {
      for (int j = 0; j < dims.y(); ++j) {
        for (int i = 0; i < dims.x(); ++i) {
          const int c[3] = {i, j, k};
          const size_t idx = (static_cast<size_t>(k) * dims.y() + j) * dims.x() + i;
          bool b = false;
          for (int d = -reach[a]; d <= reach[a] && !b; ++d) {
            const int x = c[a] + d;
            b = x < 0 || x >= dims[a] ||
                tmp[idx + static_cast<std::ptrdiff_t>(d) * static_cast<std::ptrdiff_t>(stride[a])];
          }
          blocked[idx] = b;
        }
      }
    }
  }
  reach_.assign(n, 0);
  const Eigen::Vector3i s = gt.key_of(start);
  if (!gt.in_grid(s) || blocked[gt.index(s)]) return;
  std::vector<Eigen::Vector3i> queue{s};
  reach_[gt.index(s)] = 1;
  for (size_t q = 0; q < queue.size(); ++q) {
    for (const auto& d : kNeighbours) {
      const Eigen::Vector3i nb = queue[q] + Eigen::Vector3i(d[0], d[1], d[2]);
      if (!gt.in_grid(nb)) continue;
      const size_t i = gt.index(nb);
      if (blocked[i] || reach_[i]) continue;
      reach_[i] = 1;
      queue.push_back(nb);
    }
  }
  count_ = queue.size();
}

bool VehicleReachability::reachable(const Eigen::Vector3d& p) const {
  const Eigen::Vector3i k = gt_.key_of(p);
  return gt_.in_grid(k) && reach_[gt_.index(k)];
}

}  // namespace semx::simulator
