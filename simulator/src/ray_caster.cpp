#include "semx/simulator/ray_caster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "semx/simulator/mesh.hpp"

namespace semx::simulator {

namespace {

std::optional<RayHit> intersect_cs(const Solid& s, double c, double sn, const Eigen::Vector3d& origin,
                                   const Eigen::Vector3d& dir, double t_min, double t_max) {
  const Eigen::Vector3d o = origin - s.center;
  const double hz = 0.5 * s.size.z();
  if (s.shape == Shape::kBox) {
    // Slab test in the box's own frame.
    const Eigen::Vector3d lo(c * o.x() + sn * o.y(), -sn * o.x() + c * o.y(), o.z());
    const Eigen::Vector3d ld(c * dir.x() + sn * dir.y(), -sn * dir.x() + c * dir.y(), dir.z());
    const Eigen::Vector3d h = 0.5 * s.size;
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    int axis = -1;
    double sign = 0;
    for (int k = 0; k < 3; ++k) {
      if (ld[k] == 0) {
        if (std::abs(lo[k]) > h[k]) return std::nullopt;
        continue;
      }
      double ta = (-h[k] - lo[k]) / ld[k], tb = (h[k] - lo[k]) / ld[k];
      double enter_sign = -1;  // entering through the -h face
      if (ta > tb) {
        std::swap(ta, tb);
        enter_sign = 1;
      }
      if (ta > t0) {
        t0 = ta;
        axis = k;
        sign = enter_sign;
      }
      t1 = std::min(t1, tb);
    }
    if (axis < 0 || t0 > t1 || t0 < t_min || t0 > t_max) return std::nullopt;
    Eigen::Vector3d ln = Eigen::Vector3d::Zero();
    ln[axis] = sign;
    RayHit hit;
    hit.t = t0;
    hit.normal = {c * ln.x() - sn * ln.y(), sn * ln.x() + c * ln.y(), ln.z()};
    return hit;
  }
  // Vertical cylinder: the side (a quadratic in x, y) or a cap (a plane), whichever is entered.
  const double r = s.radius();
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  bool side = false;
  const double a = dir.x() * dir.x() + dir.y() * dir.y();
  const double b = 2 * (o.x() * dir.x() + o.y() * dir.y());
  const double cc = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a == 0) {
    if (cc > 0) return std::nullopt;
  } else {
    const double disc = b * b - 4 * a * cc;
    if (disc < 0) return std::nullopt;
    const double sq = std::sqrt(disc);
    t0 = (-b - sq) / (2 * a);
    t1 = (-b + sq) / (2 * a);
    side = true;
  }
  if (dir.z() != 0) {
    double ta = (-hz - o.z()) / dir.z(), tb = (hz - o.z()) / dir.z();
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      side = false;
    }
    t1 = std::min(t1, tb);
  } else if (std::abs(o.z()) > hz) {
    return std::nullopt;
  }
  if (t0 > t1 || t0 < t_min || t0 > t_max) return std::nullopt;
  RayHit hit;
  hit.t = t0;
  if (side) {
    const Eigen::Vector3d p = o + t0 * dir;
    hit.normal = Eigen::Vector3d(p.x(), p.y(), 0).normalized();
  } else {
    hit.normal = {0, 0, dir.z() > 0 ? -1.0 : 1.0};
  }
  return hit;
}

}  // namespace

std::optional<RayHit> intersect(const Solid& s, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                double t_min, double t_max) {
  return intersect_cs(s, std::cos(s.yaw), std::sin(s.yaw), origin, dir, t_min, t_max);
}

RayCaster::RayCaster(World world) : world_(std::move(world)) {
  for (const auto& s : world_.solids) {
    cos_.push_back(std::cos(s.yaw));
    sin_.push_back(std::sin(s.yaw));
  }
}

std::optional<RayHit> RayCaster::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                                      double t_max) const {
  std::optional<RayHit> best;
  for (size_t i = 0; i < world_.solids.size(); ++i) {
    auto hit = intersect_cs(world_.solids[i], cos_[i], sin_[i], origin, dir, t_min, best ? best->t : t_max);
    if (hit) {
      hit->solid = static_cast<int>(i);
      best = hit;
    }
  }
  return best;
}

void RayCaster::render(const runtime::PinholeCamera& camera, const Eigen::Isometry3d& pose, unsigned channels,
                       CameraFrame& out, double rgb_far) const {
  const int w = camera.width, h = camera.height;
  out.camera = camera;
  out.pose = pose;
  out.channels = channels;
  if (channels & kRenderDepth) out.depth.resize(w, h);
  if (channels & kRenderLabels) {
    out.class_label.resize(w, h);
    out.instance_label.resize(w, h);
  }
  // Runs are derived from the image here: the reference renderer need not be fast.
  const bool rgb = channels & (kRenderRgb | kRenderRgbRuns);
  if (rgb) out.rgb.resize(w, h);
  const double far = std::max(camera.max_range, rgb ? rgb_far : 0.0);
  const Eigen::Vector3d origin = pose.translation();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      // The optical-frame ray has z = 1, so the ray parameter is the depth z.
      const Eigen::Vector3d dir = pose.linear() * camera.ray(u, v);
      const auto hit = cast(origin, dir, 1e-9, far);
      const bool in_range = hit && hit->t <= camera.max_range;
      if (channels & kRenderDepth) {
        uint16_t d = runtime::kDepthNoReturn;
        if (in_range) {
          d = hit->t < camera.min_range
                  ? runtime::kDepthInvalid
                  : static_cast<uint16_t>(std::min(std::lround(hit->t * 1000.0), 65534L));
        }
        out.depth.at(u, v) = d;
      }
      if (channels & kRenderLabels) {
        const Solid* s = in_range ? &world_.solids[hit->solid] : nullptr;
        out.class_label.at(u, v) = s ? static_cast<uint16_t>(s->cls) : 0;
        out.instance_label.at(u, v) = s ? s->instance : 0;
      }
      if (rgb) {
        out.rgb.at(u, v) =
            hit ? WorldMesh::shade(world_.solids[hit->solid].color, hit->normal) : kBackgroundRgb;
      }
    }
  }
  if (channels & kRenderRgbRuns) out.rgb_runs = rgb_runs(out.rgb);
}

}  // namespace semx::simulator
