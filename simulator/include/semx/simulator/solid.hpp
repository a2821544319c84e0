// The building blocks of a world: yawed boxes and vertical cylinders, each labelled with a
// semantic class and an instance. Walls, floor and ceiling are solids like any furniture.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semx/runtime/semantic_classes.hpp"
#include "semx/simulator/image.hpp"

namespace semx::simulator {

using runtime::SemanticClass;

struct Aabb {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  Eigen::Vector3d center() const { return 0.5 * (min + max); }
  Eigen::Vector3d size() const { return max - min; }
  bool contains(const Eigen::Vector3d& p, double tol = 0.0) const {
    return (p.array() >= min.array() - tol).all() && (p.array() <= max.array() + tol).all();
  }
  bool contains(const Aabb& o, double tol = 0.0) const {
    return contains(o.min, tol) && contains(o.max, tol);
  }
  // Positive-volume overlap: boxes that only touch do not overlap.
  bool overlaps(const Aabb& o) const {
    return (min.array() < o.max.array()).all() && (o.min.array() < max.array()).all();
  }
  void extend(const Aabb& o) {
    min = min.cwiseMin(o.min);
    max = max.cwiseMax(o.max);
  }
};

enum class Shape : uint8_t { kBox, kCylinder };

// Every rotation in a world is a yaw about the vertical, which keeps collision and
// voxelisation exact and cheap (a 2D problem times a z interval).
struct Solid {
  Shape shape = Shape::kBox;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  // Box: full extents along its own x, y (rotated by yaw) and z. Cylinder: (2r, 2r, height).
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  double yaw = 0.0;  // rad about world z; boxes only
  SemanticClass cls = SemanticClass::kNone;
  uint16_t instance = 0;  // 0 = none; several solids may share one instance (a multi-part object)
  Rgb color;

  static Solid box(SemanticClass cls, const Eigen::Vector3d& center, const Eigen::Vector3d& size,
                   double yaw = 0.0);
  static Solid cylinder(SemanticClass cls, const Eigen::Vector3d& center, double radius, double height);

  double radius() const { return 0.5 * size.x(); }
  double z_min() const { return center.z() - 0.5 * size.z(); }
  double z_max() const { return center.z() + 0.5 * size.z(); }
  Aabb bounds() const;
  bool contains(const Eigen::Vector3d& p) const;
  // Floor-plan footprint area in m².
  double footprint_area() const;
};

// Default display colour of a class.
Rgb class_color(SemanticClass cls);

}  // namespace semx::simulator
