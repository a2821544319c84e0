#include "semx/fixtures/synthetic_world.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "semx/map/raycast.hpp"

namespace semx::planner {

using map::VoxelKey;
using map::VoxelState;

namespace {

constexpr double kEps = 1e-9;

Box box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return {Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)};
}

struct Door {
  double centre, width;
};

// A wall of thickness t centred on x = c (or y = c) from a to b, height h, with doorways up to a
// lintel at `lintel`.
void wall(std::vector<Box>& out, bool along_y, double c, double a, double b, double t, double h,
          std::vector<Door> doors, double lintel = 2.1) {
  std::sort(doors.begin(), doors.end(), [](const Door& x, const Door& y) { return x.centre < y.centre; });
  double from = a;
  auto piece = [&](double s0, double s1, double z0, double z1) {
    if (s1 - s0 <= kEps || z1 - z0 <= kEps) return;
    out.push_back(along_y ? box(c - t / 2, s0, z0, c + t / 2, s1, z1)
                          : box(s0, c - t / 2, z0, s1, c + t / 2, z1));
  };
  for (const Door& d : doors) {
    piece(from, d.centre - d.width / 2, 0, h);
    piece(d.centre - d.width / 2, d.centre + d.width / 2, lintel, h);
    from = d.centre + d.width / 2;
  }
  piece(from, b, 0, h);
}

}  // namespace

SyntheticWorld::SyntheticWorld(double resolution, const Box& interior, std::vector<Box> solids,
                               const Eigen::Vector3d& start, std::string name)
    : km_(resolution),
      interior_(interior),
      solids_(std::move(solids)),
      start_(start),
      name_(std::move(name)) {
  const double r = resolution;
  build([&](const VoxelKey& k) {
    const Eigen::Vector3d v0(k.x * r, k.y * r, k.z * r), v1 = v0 + Eigen::Vector3d::Constant(r);
    for (const Box& s : solids_) {
      if ((v0.array() < s.max.array() - kEps).all() && (v1.array() > s.min.array() + kEps).all()) return true;
    }
    return false;
  });
}

SyntheticWorld::SyntheticWorld(double resolution, const Box& interior,
                               const std::function<bool(const VoxelKey&)>& occupied,
                               const Eigen::Vector3d& start, std::string name)
    : km_(resolution), interior_(interior), start_(start), name_(std::move(name)) {
  build(occupied);
}

void SyntheticWorld::build(const std::function<bool(const VoxelKey&)>& solid) {
  const double r = km_.resolution();
  lo_ = km_.key(interior_.min - Eigen::Vector3d::Constant(0.5 * r));
  hi_ = km_.key(interior_.max + Eigen::Vector3d::Constant(0.5 * r));
  for (int a = 0; a < 3; ++a) {
    lo_[a] -= 1;
    hi_[a] += 1;
  }
  const size_t n = static_cast<size_t>(hi_.x - lo_.x + 1) * (hi_.y - lo_.y + 1) * (hi_.z - lo_.z + 1);
  occupied_.assign(n, 0);
  free_count_ = 0;
  for (int32_t z = lo_.z; z <= hi_.z; ++z) {
    for (int32_t y = lo_.y; y <= hi_.y; ++y) {
      for (int32_t x = lo_.x; x <= hi_.x; ++x) {
        const VoxelKey k{x, y, z};
        const Eigen::Vector3d v0(x * r, y * r, z * r), v1 = v0 + Eigen::Vector3d::Constant(r);
        const bool inside = (v0.array() >= interior_.min.array() - kEps).all() &&
                            (v1.array() <= interior_.max.array() + kEps).all();
        const bool occ = !inside || solid(k);
        occupied_[index(k)] = occ ? 1 : 0;
        if (!occ) ++free_count_;
      }
    }
  }
}

SyntheticWorld SyntheticWorld::room(const Eigen::Vector3d& size, const Eigen::Vector3d& start,
                                    double resolution) {
  return SyntheticWorld(resolution, Box{Eigen::Vector3d::Zero(), size}, std::vector<Box>{}, start, "room");
}

SyntheticWorld SyntheticWorld::two_rooms(double resolution) {
  std::vector<Box> s;
  wall(s, true, 4.1, 0.0, 4.0, 0.2, 2.5, {{2.0, 1.2}});
  const std::vector<Box> furniture{
      box(0.0, 0.0, 0.0, 0.8, 1.6, 0.75),  // a table in the first room
      box(7.4, 2.6, 0.0, 8.2, 4.0, 1.9),   // a shelf in the second
  };
  s.insert(s.end(), furniture.begin(), furniture.end());
  SyntheticWorld w(resolution, {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(8.2, 4.0, 2.5)}, std::move(s),
                   Eigen::Vector3d(1.8, 2.0, 1.2), "two_rooms");
  w.set_objects(furniture);
  return w;
}

SyntheticWorld SyntheticWorld::apartment(double resolution) {
  const double h = 2.7, t = 0.2;
  std::vector<Box> s;
  // Corridor between y = 5.5 and y = 7.0, the whole length.
  wall(s, false, 5.5, 0.0, 16.0, t, h, {{2.75, 1.1}, {8.25, 1.1}, {13.5, 1.1}});
  wall(s, false, 7.0, 0.0, 16.0, t, h, {{3.0, 1.1}, {8.5, 1.1}, {13.5, 1.1}});
  // Partitions: south rooms split at x = 5.5 and 11, north ones at x = 6 and 11; the middle
  // south and north rooms also open into their east neighbours.
  wall(s, true, 5.5, 0.0, 5.4, t, h, {});
  wall(s, true, 11.0, 0.0, 5.4, t, h, {{2.5, 1.1}});
  wall(s, true, 6.0, 7.1, 12.0, t, h, {});
  wall(s, true, 11.0, 7.1, 12.0, t, h, {{9.5, 1.1}});
  // Furniture.
  const std::vector<Box> furniture{
      box(0.3, 0.3, 0.0, 2.3, 1.2, 0.75),      // desk, room S1
      box(3.5, 3.0, 0.0, 5.3, 5.2, 0.55),      // bed, room S1
      box(6.0, 0.0, 0.0, 7.5, 0.4, 1.9),       // shelf, room S2
      box(7.8, 2.0, 0.0, 9.4, 3.0, 0.75),      // table, room S2
      box(14.6, 0.5, 0.0, 15.8, 2.6, 0.85),    // sofa, room S3
      box(12.0, 4.6, 0.0, 13.6, 5.3, 2.0),     // wardrobe, room S3
      box(0.2, 10.6, 0.0, 2.4, 11.8, 0.55),    // bed, room N1
      box(4.4, 7.2, 0.0, 5.8, 7.8, 1.2),       // cabinet, room N1
      box(7.5, 9.6, 0.0, 9.5, 10.6, 0.75),     // dining table, room N2
      box(6.2, 11.5, 0.0, 10.8, 11.9, 0.9),    // kitchen counter, room N2
      box(13.0, 10.0, 0.0, 15.8, 11.8, 0.85),  // sofa, room N3
      box(11.3, 7.2, 0.0, 12.0, 8.2, 1.6),     // shelf, room N3
  };
  s.insert(s.end(), furniture.begin(), furniture.end());
  SyntheticWorld w(resolution, {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(16.0, 12.0, h)}, std::move(s),
                   Eigen::Vector3d(1.5, 6.25, 1.2), "apartment");
  w.set_objects(furniture);
  return w;
}

bool SyntheticWorld::in_grid(const VoxelKey& k) const {
  return k.x >= lo_.x && k.y >= lo_.y && k.z >= lo_.z && k.x <= hi_.x && k.y <= hi_.y && k.z <= hi_.z;
}

size_t SyntheticWorld::index(const VoxelKey& k) const {
  const size_t nx = static_cast<size_t>(hi_.x - lo_.x + 1), ny = static_cast<size_t>(hi_.y - lo_.y + 1);
  return static_cast<size_t>(k.x - lo_.x) +
         nx * (static_cast<size_t>(k.y - lo_.y) + ny * static_cast<size_t>(k.z - lo_.z));
}

bool SyntheticWorld::occupied(const VoxelKey& k) const { return !in_grid(k) || occupied_[index(k)] != 0; }

bool SyntheticWorld::collides(const Eigen::Vector3d& p, const Eigen::Vector3d& size) const {
  const Eigen::Vector3d lo = p - 0.5 * size, hi = p + 0.5 * size;
  const VoxelKey a = km_.key(lo), b = km_.key(hi);
  for (int32_t z = a.z; z <= b.z; ++z)
    for (int32_t y = a.y; y <= b.y; ++y)
      for (int32_t x = a.x; x <= b.x; ++x)
        if (occupied(VoxelKey{x, y, z})) return true;
  return false;
}

std::vector<map::VoxelChange> SyntheticWorld::observe(map::StateGrid& known, const Eigen::Vector3d& position,
                                                      double yaw, const runtime::PinholeCamera& cam,
                                                      int pixel_step) const {
  std::vector<map::VoxelChange> changes;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * runtime::optical_in_body();
  const Eigen::Vector3d axis = R.col(2);
  std::vector<VoxelKey> keys;
  auto set = [&](const VoxelKey& k, VoxelState s) {
    const VoxelState before = known.state(k);
    if (before == s) return;
    known.set_state(k, s);
    changes.push_back({k, s, before});
  };
  const int step = std::max(1, pixel_step);
  for (int v = step / 2; v < cam.height; v += step) {
    for (int u = step / 2; u < cam.width; u += step) {
      const Eigen::Vector3d dir = R * cam.ray(u, v);  // z-depth 1
      const Eigen::Vector3d end = position + cam.max_range * dir;
      keys.clear();
      bool hit = false;
      map::traverse_segment(km_, position, end, [&](const VoxelKey& k) {
        keys.push_back(k);
        if (occupied(k)) {
          hit = true;
          return false;
        }
        return true;
      });
      if (keys.empty()) continue;
      if (hit) {
        const double depth = (km_.center(keys.back()) - position).dot(axis);
        if (depth < cam.min_range) continue;
        for (size_t i = 0; i + 1 < keys.size(); ++i) set(keys[i], VoxelState::kFree);
        set(keys.back(), VoxelState::kOccupied);
      } else {
        for (size_t i = 0; i + 1 < keys.size(); ++i) set(keys[i], VoxelState::kFree);
      }
    }
  }
  return changes;
}

std::vector<map::VoxelChange> SyntheticWorld::reveal(map::StateGrid& known, const Box& b) const {
  std::vector<map::VoxelChange> changes;
  const VoxelKey a = km_.key(b.min), c = km_.key(b.max);
  for (int32_t z = a.z; z <= c.z; ++z)
    for (int32_t y = a.y; y <= c.y; ++y)
      for (int32_t x = a.x; x <= c.x; ++x) {
        const VoxelKey k{x, y, z};
        const VoxelState s = occupied(k) ? VoxelState::kOccupied : VoxelState::kFree;
        if (known.state(k) != s) {
          known.set_state(k, s);
          changes.push_back({k, s});
        }
      }
  return changes;
}

map::StateGrid SyntheticWorld::full_map() const {
  map::StateGrid g(resolution());
  for (int32_t z = lo_.z; z <= hi_.z; ++z)
    for (int32_t y = lo_.y; y <= hi_.y; ++y)
      for (int32_t x = lo_.x; x <= hi_.x; ++x)
        g.set_state({x, y, z}, occupied(VoxelKey{x, y, z}) ? VoxelState::kOccupied : VoxelState::kFree);
  return g;
}

double SyntheticWorld::coverage(const map::StateGrid& known) const {
  if (free_count_ == 0) return 0.0;
  int64_t seen = 0;
  map::StateGrid::Reader r = known.reader();
  for (int32_t z = lo_.z; z <= hi_.z; ++z)
    for (int32_t y = lo_.y; y <= hi_.y; ++y)
      for (int32_t x = lo_.x; x <= hi_.x; ++x) {
        const VoxelKey k{x, y, z};
        if (!occupied_[index(k)] && r.state(k) != VoxelState::kUnknown) ++seen;
      }
  return static_cast<double>(seen) / static_cast<double>(free_count_);
}

}  // namespace semx::planner
