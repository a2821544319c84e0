#include "semx/fixtures/synthetic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace semx::controller {

double Box::distance(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  const Eigen::Vector3d q = (p - c).cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

double SyntheticScene::exact_distance(const Eigen::Vector3d& p) const {
  double d = 1e9;
  for (const auto& b : boxes) d = std::min(d, b.distance(p));
  return d;
}

GridDistanceField rasterize_boxes(const std::vector<Box>& boxes, const Eigen::Vector3d& origin,
                                  double resolution, int nx, int ny, int nz, double max_distance,
                                  OutsideWindow outside) {
  std::vector<float> v(static_cast<std::size_t>(nx) * ny * nz, static_cast<float>(max_distance));
  const int n[3] = {nx, ny, nz};
  // Each box only matters within max_distance of itself.
  for (const auto& b : boxes) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor((b.lo[a] - max_distance - origin[a]) / resolution)));
      hi[a] =
          std::min(n[a] - 1, static_cast<int>(std::ceil((b.hi[a] + max_distance - origin[a]) / resolution)));
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const Eigen::Vector3d p =
              origin + (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * resolution;
          float& cell = v[static_cast<std::size_t>(x) +
                          static_cast<std::size_t>(nx) * (y + static_cast<std::size_t>(ny) * z)];
          cell = std::min(cell, static_cast<float>(std::max(-max_distance, b.distance(p))));
        }
      }
    }
  }
  return GridDistanceField(origin, resolution, nx, ny, nz, std::move(v), max_distance, outside);
}

SyntheticScene make_cluttered_scene(uint64_t seed, const SceneOptions& o) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const auto uni = [&](double a, double b) { return a + (b - a) * u01(rng); };

  SyntheticScene s;
  const int segments = std::max(1, o.waypoints - 1);
  const double step = o.path_length / segments;
  double heading = uni(-M_PI, M_PI);
  s.path.emplace_back(0.0, 0.0, uni(1.0, 1.6));
  for (int i = 0; i < segments; ++i) {
    if (i > 0) heading += uni(-o.max_turn, o.max_turn);
    const double dz = uni(-0.25, 0.25);
    const double horizontal = std::sqrt(std::max(0.0, step * step - dz * dz));
    Eigen::Vector3d next =
        s.path.back() + Eigen::Vector3d(horizontal * std::cos(heading), horizontal * std::sin(heading), dz);
    next.z() = std::clamp(next.z(), 0.9, 2.1);
    s.path.push_back(next);
    s.yaws.push_back(heading);
  }
  s.yaws.push_back(s.yaws.back());

  Eigen::Vector3d lo = s.path.front(), hi = s.path.front();
  for (const auto& p : s.path) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double pad = 1.5;
  Eigen::Vector3d origin(lo.x() - pad, lo.y() - pad, 0.0);
  origin = (origin / o.resolution).array().floor().matrix() * o.resolution;
  const int nx = static_cast<int>(std::ceil((hi.x() + pad - origin.x()) / o.resolution));
  const int ny = static_cast<int>(std::ceil((hi.y() + pad - origin.y()) / o.resolution));
  const int nz = static_cast<int>(std::ceil(3.0 / o.resolution));

  // Distance of a box from the path, sampled every 2 cm.
  const auto path_distance = [&](const Box& b) {
    double d = 1e9;
    for (std::size_t i = 0; i + 1 < s.path.size(); ++i) {
      const Eigen::Vector3d a = s.path[i], e = s.path[i + 1];
      const int k = std::max(1, static_cast<int>(std::ceil((e - a).norm() / 0.02)));
      for (int j = 0; j <= k; ++j) d = std::min(d, b.distance(a + (e - a) * (static_cast<double>(j) / k)));
    }
    return d;
  };

  if (o.floor_and_ceiling) {
    const double big = 100.0;
    s.boxes.push_back({Eigen::Vector3d(-big, -big, -1.0), Eigen::Vector3d(big, big, 0.0)});
    s.boxes.push_back({Eigen::Vector3d(-big, -big, 3.0), Eigen::Vector3d(big, big, 4.0)});
  }
  for (int i = 0; i < o.obstacles; ++i) {
    // Clutter concentrates near the path: anchored at a random point of it, then pushed out.
    for (int attempt = 0; attempt < 30; ++attempt) {
      const std::size_t seg = static_cast<std::size_t>(rng() % static_cast<uint64_t>(segments));
      const Eigen::Vector3d anchor = s.path[seg] + (s.path[seg + 1] - s.path[seg]) * u01(rng);
      const double r = uni(0.3, 2.0), a = uni(-M_PI, M_PI);
      const Eigen::Vector3d c = anchor + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), uni(-0.8, 0.8));
      const Eigen::Vector3d h(uni(0.1, 0.5), uni(0.1, 0.5), uni(0.15, 1.5));
      Box b{c - h, c + h};
      if (path_distance(b) >= o.min_clearance) {
        s.boxes.push_back(b);
        break;
      }
    }
  }
  // Interpolating the grid loses a few centimetres where two boxes' fields meet; drop the box
  // nearest any point of the path where the grid says less than min_clearance - 2.5 cm, so the
  // path stays a valid (fallback) answer on the grid too.
  const std::size_t first_box = o.floor_and_ceiling ? 2 : 0;
  for (;;) {
    s.field =
        rasterize_boxes(s.boxes, origin, o.resolution, nx, ny, nz, o.max_distance, OutsideWindow::kFree);
    std::ptrdiff_t culprit = -1;
    for (std::size_t i = 0; i + 1 < s.path.size() && culprit < 0; ++i) {
      const Eigen::Vector3d a = s.path[i], e = s.path[i + 1];
      const int k = std::max(1, static_cast<int>(std::ceil((e - a).norm() / 0.02)));
      for (int j = 0; j <= k && culprit < 0; ++j) {
        const Eigen::Vector3d p = a + (e - a) * (static_cast<double>(j) / k);
        if (s.field.distance(p) >= o.min_clearance - 0.025) continue;
        double best = 1e9;
        for (std::size_t b = first_box; b < s.boxes.size(); ++b) {
          const double d = s.boxes[b].distance(p);
          if (d < best) {
            best = d;
            culprit = static_cast<std::ptrdiff_t>(b);
          }
        }
      }
    }
    if (culprit < 0) break;
    s.boxes.erase(s.boxes.begin() + culprit);
  }
  return s;
}

}  // namespace semx::controller
