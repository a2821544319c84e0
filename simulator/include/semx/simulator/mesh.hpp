// The solids of a world as triangles, built once: boxes as 12 triangles, cylinders as N-gon
// prisms. The rasteriser draws these; per-triangle labels and shaded colours are looked up
// after the depth test so the inner loop writes only a depth and a triangle index.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct MeshOptions {
  // Facets per cylinder. The facet radius is chosen so the prism's surface lies within
  // ±r(1-cos(π/N))/(1+cos(π/N)) of the true cylinder (±1.2 mm for r = 0.5 m at N = 32).
  int cylinder_segments = 32;
};

class WorldMesh {
 public:
  struct SolidRange {
    uint32_t first_vertex = 0, vertex_count = 0;
    uint32_t first_triangle = 0, triangle_count = 0;
    Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();  // bounding sphere, for culling
    double sphere_radius = 0;
  };
  struct Triangle {
    uint32_t v[3];           // indices into vertices()
    Eigen::Vector3d normal;  // outward unit normal (world)
    double offset = 0;       // plane: normal · p = offset
    uint32_t solid = 0;
  };

  WorldMesh() = default;
  explicit WorldMesh(const World& world, const MeshOptions& options = {});

  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<SolidRange>& solids() const { return solids_; }
  // Per-triangle lookups used after the depth test.
  const std::vector<uint16_t>& triangle_class() const { return tri_class_; }
  const std::vector<uint16_t>& triangle_instance() const { return tri_instance_; }
  const std::vector<Rgb>& triangle_rgb() const { return tri_rgb_; }

  // Flat Lambert shading of a class colour for a face normal: two fixed directional lights
  // (key from above, fill from below) plus ambient, so every face of a room is distinguishable.
  static Rgb shade(const Rgb& color, const Eigen::Vector3d& normal);

 private:
  void add_box(const Solid& s, uint32_t index);
  void add_cylinder(const Solid& s, uint32_t index, int segments);
  void add_triangle(uint32_t a, uint32_t b, uint32_t c, const Solid& s, uint32_t index);

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<SolidRange> solids_;
  std::vector<uint16_t> tri_class_, tri_instance_;
  std::vector<Rgb> tri_rgb_;
};

}  // namespace semx::simulator
