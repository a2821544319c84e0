#include "semx/simulator/mesh.hpp"

#include <algorithm>
#include <cmath>

namespace semx::simulator {

WorldMesh::WorldMesh(const World& world, const MeshOptions& options) {
  const int segments = std::max(3, options.cylinder_segments);
  for (uint32_t i = 0; i < world.solids.size(); ++i) {
    const Solid& s = world.solids[i];
    SolidRange range;
    range.first_vertex = static_cast<uint32_t>(vertices_.size());
    range.first_triangle = static_cast<uint32_t>(triangles_.size());
    if (s.shape == Shape::kBox) {
      add_box(s, i);
    } else {
      add_cylinder(s, i, segments);
    }
    range.vertex_count = static_cast<uint32_t>(vertices_.size()) - range.first_vertex;
    range.triangle_count = static_cast<uint32_t>(triangles_.size()) - range.first_triangle;
    range.sphere_center = s.center;
    for (uint32_t v = range.first_vertex; v < vertices_.size(); ++v) {
      range.sphere_radius = std::max(range.sphere_radius, (vertices_[v] - s.center).norm());
    }
    solids_.push_back(range);
  }
}

void WorldMesh::add_box(const Solid& s, uint32_t index) {
  const uint32_t base = static_cast<uint32_t>(vertices_.size());
  const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
  const Eigen::Vector3d h = 0.5 * s.size;
  for (int k = 0; k < 8; ++k) {
    const double lx = (k & 1) ? h.x() : -h.x(), ly = (k & 2) ? h.y() : -h.y(), lz = (k & 4) ? h.z() : -h.z();
    vertices_.push_back(s.center + Eigen::Vector3d(c * lx - sn * ly, sn * lx + c * ly, lz));
  }
  // Faces as corner quads (bit 0 = +x, bit 1 = +y, bit 2 = +z).
  static constexpr uint32_t kQuads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                            {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  for (const auto& q : kQuads) {
    add_triangle(base + q[0], base + q[1], base + q[2], s, index);
    add_triangle(base + q[0], base + q[2], base + q[3], s, index);
  }
}

void WorldMesh::add_cylinder(const Solid& s, uint32_t index, int segments) {
  const uint32_t base = static_cast<uint32_t>(vertices_.size());
  // Vertex radius that splits the faceting error evenly inside and outside the true surface.
  const double half_angle = M_PI / segments;
  const double rv = 2.0 * s.radius() / (1.0 + std::cos(half_angle));
  for (int ring = 0; ring < 2; ++ring) {
    const double z = ring == 0 ? s.z_min() : s.z_max();
    for (int k = 0; k < segments; ++k) {
      const double a = 2.0 * M_PI * k / segments;
      vertices_.push_back({s.center.x() + rv * std::cos(a), s.center.y() + rv * std::sin(a), z});
    }
  }
  const uint32_t n = static_cast<uint32_t>(segments);
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t k1 = (k + 1) % n;
    add_triangle(base + k, base + k1, base + n + k1, s, index);
    add_triangle(base + k, base + n + k1, base + n + k, s, index);
  }
  for (uint32_t k = 1; k + 1 < n; ++k) {
    add_triangle(base, base + k, base + k + 1, s, index);
    add_triangle(base + n, base + n + k, base + n + k + 1, s, index);
  }
}

void WorldMesh::add_triangle(uint32_t a, uint32_t b, uint32_t c, const Solid& s, uint32_t index) {
  Triangle t;
  t.v[0] = a;
  t.v[1] = b;
  t.v[2] = c;
  const Eigen::Vector3d& p0 = vertices_[a];
  Eigen::Vector3d n = (vertices_[b] - p0).cross(vertices_[c] - p0).normalized();
  // Solids are convex, so the outward side is the one away from the centre.
  const Eigen::Vector3d centroid = (p0 + vertices_[b] + vertices_[c]) / 3.0;
  if (n.dot(centroid - s.center) < 0) {
    n = -n;
    std::swap(t.v[1], t.v[2]);
  }
  t.normal = n;
  t.offset = n.dot(p0);
  t.solid = index;
  triangles_.push_back(t);
  tri_class_.push_back(static_cast<uint16_t>(s.cls));
  tri_instance_.push_back(s.instance);
  tri_rgb_.push_back(shade(s.color, n));
}

Rgb WorldMesh::shade(const Rgb& color, const Eigen::Vector3d& normal) {
  static const Eigen::Vector3d key = Eigen::Vector3d(0.4, 0.25, 0.88).normalized();
  static const Eigen::Vector3d fill = Eigen::Vector3d(-0.5, -0.7, -0.5).normalized();
  const double f = 0.35 + 0.55 * std::max(0.0, normal.dot(key)) + 0.3 * std::max(0.0, normal.dot(fill));
  auto ch = [f](uint8_t v) { return static_cast<uint8_t>(std::clamp(std::lround(v * f), 0L, 255L)); };
  return {ch(color.r), ch(color.g), ch(color.b)};
}

}  // namespace semx::simulator
