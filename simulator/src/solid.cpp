#include "semx/simulator/solid.hpp"

#include <cmath>

namespace semx::simulator {

Solid Solid::box(SemanticClass cls, const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw) {
  Solid s;
  s.shape = Shape::kBox;
  s.center = center;
  s.size = size;
  s.yaw = yaw;
  s.cls = cls;
  s.color = class_color(cls);
  return s;
}

Solid Solid::cylinder(SemanticClass cls, const Eigen::Vector3d& center, double radius, double height) {
  Solid s;
  s.shape = Shape::kCylinder;
  s.center = center;
  s.size = {2 * radius, 2 * radius, height};
  s.cls = cls;
  s.color = class_color(cls);
  return s;
}

Aabb Solid::bounds() const {
  Eigen::Vector3d half;
  if (shape == Shape::kCylinder) {
    half = 0.5 * size;
  } else {
    const double c = std::abs(std::cos(yaw)), s = std::abs(std::sin(yaw));
    half = {0.5 * (c * size.x() + s * size.y()), 0.5 * (s * size.x() + c * size.y()), 0.5 * size.z()};
  }
  return {center - half, center + half};
}

bool Solid::contains(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = p - center;
  if (std::abs(d.z()) > 0.5 * size.z()) return false;
  if (shape == Shape::kCylinder) return d.head<2>().norm() <= radius();
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double lx = c * d.x() + s * d.y(), ly = -s * d.x() + c * d.y();
  return std::abs(lx) <= 0.5 * size.x() && std::abs(ly) <= 0.5 * size.y();
}

double Solid::footprint_area() const {
  return shape == Shape::kCylinder ? M_PI * radius() * radius() : size.x() * size.y();
}

Rgb class_color(SemanticClass cls) {
  const auto& c = runtime::class_info(cls).rgb;
  return {c[0], c[1], c[2]};
}

}  // namespace semx::simulator
