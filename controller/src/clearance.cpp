#include "semx/controller/clearance.hpp"

#include <algorithm>
#include <cmath>

namespace semx::controller {

double footprint_reach(const Eigen::Vector3d& n, double yaw, double half_xy, double half_z) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return half_xy * (std::abs(c * n.x() + s * n.y()) + std::abs(-s * n.x() + c * n.y())) +
         half_z * std::abs(n.z());
}

ClearanceReport check_clearance(const Trajectory& trajectory, const DistanceField& field, double t0,
                                double t1, const ClearanceRule& rule) {
  ClearanceReport r;
  if (trajectory.empty()) return r;
  t0 = std::clamp(t0, 0.0, trajectory.duration());
  t1 = std::clamp(t1, t0, trajectory.duration());
  const double vmax = trajectory.max_speed();
  const double span = t1 - t0;
  const int n = vmax * span > 0 ? static_cast<int>(std::ceil(vmax * span / rule.spacing)) : 0;
  const double pad = 0.5 * field.lipschitz() * rule.spacing;

  const auto fail = [&](double t, const Eigen::Vector3d& p, double d) {
    r.ok = false;
    r.violation_time = t;
    r.violation_point = p;
    r.violation_distance = d;
  };

  const bool footprint = rule.footprint_half_xy > 0.0 && !trajectory.yaw.empty();
  double start = 0.0;
  bool escaping = false;
  // Below hard_bound at the start: the floor rises with the arc length from the start's value.
  bool contact = false;
  double contact_floor = 0.0, arc = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  // How far below the turned body's reach a sample may be: a start already below it (the vehicle
  // stands there), or the sample where an escape from the bound ends, may move out of it, never
  // deeper, as an escape from the bound may.
  double reach_deficit_allowed = 0.0;
  bool reach_escape_may_start = true;
  for (int i = 0; i <= n; ++i) {
    const double t = n == 0 ? t0 : t0 + span * i / n;
    const Eigen::Vector3d p = trajectory.position_at(t);
    Eigen::Vector3d g;
    const double d = field.distance(p, footprint ? &g : nullptr);
    ++r.samples;
    if (d < r.min_distance) {
      r.min_distance = d;
      r.min_time = t;
    }
    const double low = d - pad;  // what the field may be anywhere near this sample
    if (i == 0) {
      start = d;
      escaping = low < rule.bound;
      r.escaping = escaping;
      contact = escaping && low < rule.hard_bound;
      contact_floor = low - rule.escape_slack;
      if (escaping && (!rule.allow_escape || (contact && !(rule.contact_rise > 0.0)))) {
        fail(t, p, d);
        return r;
      }
    } else {
      arc += (p - previous).norm();
    }
    previous = p;
    const double floor =
        contact ? std::min(rule.hard_bound, contact_floor + rule.contact_rise * arc) : rule.hard_bound;
    if (escaping) {
      if (low >= rule.bound) {
        escaping = false;  // out: from here on the full bound applies
        reach_escape_may_start = true;
      } else if (low < floor || d < start - rule.escape_slack) {
        fail(t, p, d);
        return r;
      }
    } else if (low < rule.bound) {
      fail(t, p, d);
      return r;
    }
    if (!escaping && footprint && g.norm() > kRidgeGradient) {
      // The gradient points away from the nearest obstacle; the reach is symmetric.
      const Eigen::Vector3d n = g.normalized();
      const double deficit = footprint_reach(n, trajectory.yaw.evaluate(t, 0)(0), rule.footprint_half_xy,
                                             rule.footprint_half_z) +
                             rule.footprint_margin - low;
      if (reach_escape_may_start && deficit > 0.0 && rule.allow_escape)
        reach_deficit_allowed = deficit + rule.escape_slack;
      if (deficit <= 0.0) {
        reach_deficit_allowed = 0.0;  // out: from here on the full reach applies
      } else if (deficit > reach_deficit_allowed) {
        r.footprint = true;
        r.violation_normal = n;
        r.reach_allowed = low - rule.footprint_margin + reach_deficit_allowed;
        fail(t, p, d);
        return r;
      }
    }
    reach_escape_may_start = false;
  }
  if (escaping && rule.require_exit) {
    const Eigen::Vector3d end = trajectory.position_at(t1);
    fail(t1, end, field.distance(end));
  }
  return r;
}

}  // namespace semx::controller
