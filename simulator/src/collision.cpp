#include "semx/simulator/collision.hpp"

#include <algorithm>
#include <cmath>

namespace semx::simulator {
namespace {

// Below this a gap counts as contact, not overlap: solids laid flush (a wall on the floor, a
// voxel face on a wall face) must not collide because of rounding.
constexpr double kEps = 1e-9;

bool z_overlap(double ca, double ha, double cb, double hb) { return std::abs(ca - cb) < ha + hb - kEps; }

struct Rect {
  Eigen::Vector2d c;
  Eigen::Vector2d half;
  Eigen::Vector2d ax, ay;  // unit axes
};

Rect rect_of(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {center.head<2>(), 0.5 * size.head<2>(), {c, s}, {-s, c}};
}

double projected_radius(const Rect& r, const Eigen::Vector2d& axis) {
  return r.half.x() * std::abs(r.ax.dot(axis)) + r.half.y() * std::abs(r.ay.dot(axis));
}

bool rects_overlap(const Rect& a, const Rect& b) {
  const Eigen::Vector2d d = b.c - a.c;
  for (const Eigen::Vector2d& axis : {a.ax, a.ay, b.ax, b.ay}) {
    if (std::abs(d.dot(axis)) >= projected_radius(a, axis) + projected_radius(b, axis) - kEps) return false;
  }
  return true;
}

bool rect_circle_overlap(const Rect& r, const Eigen::Vector2d& c, double radius) {
  const Eigen::Vector2d d = c - r.c;
  const double lx = std::clamp(d.dot(r.ax), -r.half.x(), r.half.x());
  const double ly = std::clamp(d.dot(r.ay), -r.half.y(), r.half.y());
  const Eigen::Vector2d closest = lx * r.ax + ly * r.ay;
  return (d - closest).squaredNorm() < (radius - kEps) * (radius - kEps) && radius > kEps;
}

bool box_vs_solid(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw,
                  const Solid& solid) {
  if (!z_overlap(center.z(), 0.5 * size.z(), solid.center.z(), 0.5 * solid.size.z())) return false;
  const Rect a = rect_of(center, size, yaw);
  if (solid.shape == Shape::kCylinder) return rect_circle_overlap(a, solid.center.head<2>(), solid.radius());
  return rects_overlap(a, rect_of(solid.center, solid.size, solid.yaw));
}

}  // namespace

Aabb YawBox::bounds() const {
  Solid s = Solid::box(SemanticClass::kNone, center, size, yaw);
  return s.bounds();
}

bool overlaps(const YawBox& box, const Solid& solid) {
  if (!box.bounds().overlaps(solid.bounds())) return false;
  return box_vs_solid(box.center, box.size, box.yaw, solid);
}

bool overlaps(const YawBox& a, const YawBox& b) {
  if (!z_overlap(a.center.z(), 0.5 * a.size.z(), b.center.z(), 0.5 * b.size.z())) return false;
  return rects_overlap(rect_of(a.center, a.size, a.yaw), rect_of(b.center, b.size, b.yaw));
}

bool overlaps(const Aabb& box, const Solid& solid) {
  return box_vs_solid(box.center(), box.size(), 0.0, solid);
}

}  // namespace semx::simulator
