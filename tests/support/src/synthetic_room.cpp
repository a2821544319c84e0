#include "semx/fixtures/synthetic_room.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace semx::mapper {

SyntheticRoom::SyntheticRoom(const Aabb& interior, std::vector<Aabb> boxes)
    : interior_(interior), boxes_(std::move(boxes)) {}

SyntheticRoom SyntheticRoom::furnished() {
  return SyntheticRoom({{0.0, 0.0, 0.0}, {6.0, 5.0, 2.7}}, {
                                                               {{1.0, 1.0, 0.0}, {2.2, 1.8, 0.75}},  // table
                                                               {{5.1, 0.3, 0.0}, {5.8, 1.0, 2.0}},  // cabinet
                                                               {{3.6, 4.0, 0.0}, {5.6, 4.8, 0.85}},  // sofa
                                                               {{2.0, 3.4, 0.0}, {2.3, 3.7, 2.7}},   // pillar
                                                           });
}

double SyntheticRoom::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double best = kInf;
  if (interior_.contains(o)) {
    for (int a = 0; a < 3; ++a) {
      if (d[a] > 0) best = std::min(best, (interior_.max[a] - o[a]) / d[a]);
      if (d[a] < 0) best = std::min(best, (interior_.min[a] - o[a]) / d[a]);
    }
  }
  for (const Aabb& b : boxes_) {
    double t0 = 0.0, t1 = kInf;
    for (int a = 0; a < 3 && t0 <= t1; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < b.min[a] || o[a] > b.max[a]) t0 = kInf;
        continue;
      }
      double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 <= t1) best = std::min(best, t0);
  }
  return best;
}

std::vector<uint16_t> SyntheticRoom::render(const runtime::PinholeCamera& cam,
                                            const Eigen::Isometry3d& T) const {
  std::vector<uint16_t> depth(static_cast<size_t>(cam.width) * cam.height);
  const Eigen::Matrix3d r = T.linear();
  const Eigen::Vector3d o = T.translation();
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      // The optical ray has z = 1, so the hit parameter is the z-depth.
      const double t = cast(o, r * cam.ray(u, v));
      uint16_t mm;
      if (!(t <= cam.max_range)) {
        mm = runtime::kDepthNoReturn;
      } else if (t < cam.min_range) {
        mm = runtime::kDepthInvalid;
      } else {
        mm = static_cast<uint16_t>(std::min<long>(std::lround(t * 1000.0), runtime::kDepthMaxEncodable));
      }
      depth[static_cast<size_t>(v) * cam.width + u] = mm;
    }
  }
  return depth;
}

bool SyntheticRoom::solid(const Eigen::Vector3d& p) const {
  if (!interior_.contains(p)) return true;
  return std::any_of(boxes_.begin(), boxes_.end(), [&](const Aabb& b) { return b.contains(p); });
}

Eigen::Isometry3d camera_pose(const Eigen::Vector3d& position, double yaw, double pitch) {
  const Eigen::Matrix3d r_world_body =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = r_world_body * runtime::optical_in_body();
  T.translation() = position;
  return T;
}

Eigen::Isometry3d room_loop_pose(int k, int per_loop) {
  const double s = static_cast<double>(k) / per_loop;
  const Eigen::Vector3d pos(3.0071 + 0.45 * std::cos(2 * M_PI * s), 2.5043 + 0.45 * std::sin(2 * M_PI * s),
                            1.3529 + 0.12 * std::sin(6 * M_PI * s));
  return camera_pose(pos, 3 * M_PI * s, 0.15 * std::sin(4 * M_PI * s));
}

}  // namespace semx::mapper
