#include "semx/controller/trajectory_generator.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "semx/controller/body_heading.hpp"
#include "semx/controller/fallback.hpp"
#include "semx/controller/time_allocation.hpp"
#include "semx/controller/yaw_profile.hpp"

namespace semx::controller {
namespace {

std::string describe(const ClearanceReport& c) {
  std::ostringstream s;
  s.precision(3);
  s << (c.footprint ? "the turned body's reach, " : "") << "distance " << c.violation_distance
    << " m at t = " << c.violation_time << " s (" << c.violation_point.x() << ", " << c.violation_point.y()
    << ", " << c.violation_point.z() << ")";
  return s.str();
}

}  // namespace

double TrajectoryGenerator::speed_limit(double max_speed) const {
  const double v = config_.limits.max_velocity;
  return max_speed > 0 ? std::min(v, max_speed) : v;
}

ClearanceRule TrajectoryGenerator::generation_rule(bool optimised) const {
  ClearanceRule r;
  r.bound = config_.clearance.bound();
  r.hard_bound = config_.clearance.half_size;
  r.spacing = config_.clearance.check_spacing;
  r.allow_escape = config_.clearance.allow_escape;
  if (optimised && config_.clearance.turned_body) {
    r.footprint_half_xy = config_.clearance.half_size;
    r.footprint_half_z = config_.clearance.half_height;
    r.footprint_margin = config_.clearance.footprint_margin;
  }
  return r;
}

ClearanceRule TrajectoryGenerator::flight_rule(bool optimised) const {
  ClearanceRule r = generation_rule(optimised);
  r.bound = config_.clearance.brake_bound();
  r.footprint_margin = 0.0;  // brake only when the body itself would touch, not on map jitter
  r.require_exit = false;    // a horizon may end before an escape does
  return r;
}

bool TrajectoryGenerator::finish(Trajectory& trajectory, const std::vector<double>& times,
                                 const std::vector<double>& yaws, double v_max, const DistanceField& field,
                                 GenerationResult& result) const {
  // The control-point bounds hold for the whole curve; stretching time by k divides speed by k
  // and acceleration by k², leaving the (checked) geometry as it is.
  double k = std::max({1.0, trajectory.max_speed() / v_max,
                       std::sqrt(trajectory.max_acceleration() / config_.limits.max_acceleration)});
  if (k > 1.0) k *= 1.0 + 1e-9;
  result.time_scale = k;
  trajectory.position.set_knot_interval(trajectory.knot_interval() * k);
  std::vector<double> scaled(times);
  for (double& t : scaled) t *= k;
  const PositionSpline curve = trajectory.position;  // the yaw profile may add a hover at its end
  // One heading target checked against `rule`, held where the turned body fails, at most `repairs`
  // times. Each failing instant first gets its own hold, a later one replacing the knots of an
  // earlier one it overlaps. When that does not pass, `merge`: a failure within two holds' length
  // of a held one joins it, and one heading must meet both. A doorway's two jamb ends, passed a
  // few centimetres apart, want different squares, and holding each square in turn undid the
  // other (env3, a door of the east rooms: eight repairs alternated between 173° and 23°, and the
  // path went to the fallback). But a heading that turns within the doorway may pass where no one
  // heading does (a lintel's edge, then the jambs), so merging is the second try, not the rule.
  struct Hold {
    double first, last;  // the failing instants it holds for
    double yaw_ref;      // the heading the curve had at the first of them
    HeadingRamp heading;
    std::vector<ReachLimit> limits;
  };
  const double hold = config_.clearance.heading_hold;
  // A ramp the yaw profile can follow with room to spare: it also has to turn into it.
  const double max_rate = 0.5 * config_.limits.max_yaw_rate;
  const auto check = [&](const ClearanceRule& rule, int repairs, bool merge) {
    std::vector<Hold> holds;
    result.repaired_headings = 0;
    for (int attempt = 0;; ++attempt) {
      std::vector<double> knots(scaled), targets(yaws);
      for (const Hold& h : holds) hold_heading(knots, targets, h.first, h.last, hold, h.heading);
      trajectory.position = curve;
      add_yaw_profile(trajectory, knots, targets, config_.limits.max_yaw_rate);
      result.clearance = check_clearance(trajectory, field, 0.0, trajectory.duration(), rule);
      if (result.clearance.ok || !result.clearance.footprint || attempt >= repairs) break;
      const double t = result.clearance.violation_time;
      if (!(t > knots.front() && t < knots.back()) ||
          !(result.clearance.violation_normal.head<2>().norm() > 0.0))
        break;
      const ReachLimit limit{t, result.clearance.violation_normal, result.clearance.reach_allowed};
      auto near = !merge ? holds.end() : std::find_if(holds.begin(), holds.end(), [&](const Hold& h) {
        return t >= h.first - 2.0 * hold && t <= h.last + 2.0 * hold;
      });
      if (near == holds.end()) {
        const double yaw = trajectory.yaw.evaluate(t, 0)(0);
        holds.push_back(Hold{t, t, yaw, HeadingRamp{t, yaw, 0.0}, {}});
        near = holds.end() - 1;
      }
      near->first = std::min(near->first, t);
      near->last = std::max(near->last, t);
      near->limits.push_back(limit);
      near->heading = heading_for_limits(near->yaw_ref, near->limits, max_rate, rule.footprint_half_xy,
                                         rule.footprint_half_z);
      // A hold that grew may now overlap the next: merged, they too share one heading.
      if (merge)
        std::sort(holds.begin(), holds.end(), [](const Hold& a, const Hold& b) { return a.first < b.first; });
      for (std::size_t k = 1; merge && k < holds.size();) {
        Hold& a = holds[k - 1];
        if (holds[k].first - 2.0 * hold > a.last) {
          ++k;
          continue;
        }
        a.last = std::max(a.last, holds[k].last);
        a.limits.insert(a.limits.end(), holds[k].limits.begin(), holds[k].limits.end());
        a.heading =
            heading_for_limits(a.yaw_ref, a.limits, max_rate, rule.footprint_half_xy, rule.footprint_half_z);
        holds.erase(holds.begin() + static_cast<std::ptrdiff_t>(k));
      }
      ++result.repaired_headings;
    }
    if (!result.clearance.ok) result.repaired_headings = 0;
    return result.clearance.ok;
  };
  const ClearanceRule rule = generation_rule(trajectory.optimized);
  // Only the turned-body rule depends on the heading, and only optimised curves are held to it.
  const int repairs = config_.clearance.heading_repairs;
  const bool join = repairs > 0 && config_.clearance.join_holds;
  if (rule.footprint_half_xy > 0.0)
    return check(rule, repairs, false) || (join && check(rule, repairs, true));
  // The fallback is the planner's path, whose clearance the turned body need not keep (a doorway's
  // centre line is 0.35 m from its jambs), but its heading is free: held square where the body
  // would touch when that suffices, as it is, bound only, when it does not. It had flown
  // diagonally past a wall's end 0.35 m away with its corner 0.327 m out, touched it and stayed
  // there (env3, fuel's latency tour, seed 1, at 154 s).
  if (config_.clearance.square_fallback && config_.clearance.turned_body) {
    const ClearanceRule body = generation_rule(true);
    if (check(body, repairs, false) || (join && check(body, repairs, true))) return true;
  }
  return check(rule, 0, false);
}

Eigen::Vector3d TrajectoryGenerator::start_velocity(const StartState& start, double v_max) {
  Eigen::Vector3d v0 = start.velocity.allFinite() ? start.velocity : Eigen::Vector3d::Zero();
  if (v0.norm() > v_max) v0 *= v_max / v0.norm();
  return v0;
}

PositionSpline TrajectoryGenerator::initial_spline(const std::vector<Eigen::Vector3d>& polyline,
                                                   const StartState& start, double v_max,
                                                   std::vector<double>* point_times, double v_start,
                                                   const std::vector<double>& segment_speed) const {
  const double dt = config_.trajectory.knot_interval;
  const Eigen::Vector3d v0 = start_velocity(start, std::max(v_max, v_start));
  const double along = polyline.size() > 1 ? v0.dot((polyline[1] - polyline[0]).normalized()) : 0.0;
  const TimedPolyline timed(polyline, along, v_max, config_.limits.max_acceleration, dt, segment_speed);
  if (point_times) *point_times = timed.point_times();
  const int m = std::max(2, static_cast<int>(std::ceil(timed.duration() / dt)));
  // Control point i sits near the curve at time (i-1)·dt. The first three give the start
  // exactly: p(0) = Q1, v(0) = (Q2 - Q0)/2dt, a(0) = 0; the last three stop at the goal.
  PositionSpline::Points q;
  q.push_back(start.position - dt * v0);
  q.push_back(start.position);
  q.push_back(start.position + dt * v0);
  for (int k = 2; k < m; ++k) q.push_back(timed.position(k * dt));
  for (int k = 0; k < 3; ++k) q.push_back(polyline.back());
  return PositionSpline(std::move(q), dt);
}

Eigen::Vector3d TrajectoryGenerator::nearest_on_path(const Eigen::Vector3d& p,
                                                     const std::vector<Eigen::Vector3d>& polyline) {
  Eigen::Vector3d best = polyline.front();
  double best_sq = (p - best).squaredNorm();
  for (size_t k = 0; k + 1 < polyline.size(); ++k) {
    const Eigen::Vector3d d = polyline[k + 1] - polyline[k];
    const double dd = d.squaredNorm();
    const double t = dd > 0 ? std::clamp((p - polyline[k]).dot(d) / dd, 0.0, 1.0) : 0.0;
    const Eigen::Vector3d q = polyline[k] + t * d;
    if (const double sq = (q - p).squaredNorm(); sq < best_sq) {
      best_sq = sq;
      best = q;
    }
  }
  return best;
}

double TrajectoryGenerator::deviation(const PositionSpline& curve,
                                      const std::vector<Eigen::Vector3d>& polyline, Eigen::Vector3d* where) {
  if (polyline.empty()) return 0.0;
  const double duration = curve.duration();
  const int n = std::max(1, static_cast<int>(std::ceil(duration / kDeviationStep)));
  double worst = 0.0;
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector3d p = curve.evaluate(duration * i / n, 0);
    const double off = (nearest_on_path(p, polyline) - p).norm();
    if (off > worst || i == 0) {
      worst = std::max(worst, off);
      if (where) *where = p;
    }
  }
  return worst;
}

SlowZones::Split SlowZones::split(const std::vector<Eigen::Vector3d>& polyline,
                                  const std::vector<double>& yaws, double v_slow, double v_fast) const {
  Split out;
  if (polyline.empty()) return out;
  out.points.push_back(polyline.front());
  out.yaws.push_back(yaws.empty() ? 0.0 : yaws.front());
  auto inside = [&](const Eigen::Vector3d& p) {
    return std::any_of(zones.begin(), zones.end(),
                       [&](const Zone& z) { return (p - z.centre).norm() < z.radius; });
  };
  for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
    const Eigen::Vector3d a = polyline[k], d = polyline[k + 1] - a;
    const double len = d.norm();
    const double ya = k < yaws.size() ? yaws[k] : out.yaws.back();
    const double yb = k + 1 < yaws.size() ? yaws[k + 1] : ya;
    // Where the segment enters or leaves a zone: |a + t d - c| = r.
    std::vector<double> cuts;
    const double dd = d.squaredNorm();
    for (const Zone& z : zones) {
      if (dd <= 0) break;
      const Eigen::Vector3d w = a - z.centre;
      const double b = w.dot(d), c = w.squaredNorm() - z.radius * z.radius, disc = b * b - dd * c;
      if (disc <= 0) continue;
      for (double t : {(-b - std::sqrt(disc)) / dd, (-b + std::sqrt(disc)) / dd})
        if (t * len > kMinPiece && (1 - t) * len > kMinPiece) cuts.push_back(t);
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.push_back(1.0);
    double t0 = 0.0;
    for (double t : cuts) {
      if ((t - t0) * len <= kMinPiece && t < 1.0) continue;
      out.speed.push_back(inside(a + 0.5 * (t0 + t) * d) ? v_slow : v_fast);
      out.points.push_back(t < 1.0 ? Eigen::Vector3d(a + t * d) : polyline[k + 1]);
      // The turn to the next waypoint's heading spread over the pieces by length.
      out.yaws.push_back(ya + t * (yb - ya));
      t0 = t;
    }
  }
  return out;
}

bool SlowZones::add(const Eigen::Vector3d& p, double radius) {
  for (Zone& z : zones) {
    // The same trouble again: its zone was too small.
    if ((p - z.centre).norm() < 0.5 * z.radius) {
      z.radius *= 1.5;
      return false;
    }
  }
  zones.push_back(Zone{p, radius});
  return true;
}

GenerationResult TrajectoryGenerator::generate(const Path& path, const VehicleState& vehicle,
                                               const DistanceField& field) const {
  std::vector<double> yaws;
  const auto polyline = flight_polyline(path, vehicle.position, vehicle.yaw, &yaws);
  StartState start;
  start.position = vehicle.position;
  start.velocity = vehicle.velocity;
  start.yaw = vehicle.yaw;
  return generate(polyline, yaws, start, path.max_speed, field);
}

GenerationResult TrajectoryGenerator::generate(const std::vector<Eigen::Vector3d>& polyline,
                                               const std::vector<double>& path_yaws, const StartState& start,
                                               double max_speed, const DistanceField& field) const {
  GenerationResult result;
  std::vector<double> yaws = path_yaws;
  if (config_.clearance.square_headings) {
    result.squared_headings =
        square_headings_near_obstacles(polyline, yaws, field, config_.clearance.square_within());
  }
  const double v_max = speed_limit(max_speed);
  const double a_max = config_.limits.max_acceleration;
  const double dt = config_.trajectory.knot_interval;

  const double v_fallback = v_max * config_.trajectory.fallback_speed_factor;
  const Eigen::Vector3d v0 = start_velocity(start, v_max);
  std::string why;
  if (config_.optimizer.max_iterations > 0) {
    // The deviation is measured from where the fallback would fly, braking ray included.
    const std::vector<Eigen::Vector3d> route = fallback_route(polyline, v0, a_max, dt);
    // One optimised curve cruising at `cruise` (starting at the vehicle's velocity), or along
    // `split` at its pieces' speeds; on failure, says why in `attempt` and `cause` and where in
    // `trouble`.
    std::string attempt;
    FallbackCause cause = FallbackCause::kNone;
    Eigen::Vector3d trouble = Eigen::Vector3d::Zero();
    const auto optimised = [&](double cruise, const SlowZones::Split* split) {
      std::vector<double> times;
      Trajectory smooth;
      smooth.optimized = true;
      smooth.position = split ? initial_spline(split->points, start, v_max, &times, v_max, split->speed)
                              : initial_spline(polyline, start, cruise, &times, v_max);
      result.optimizer = optimizer_.optimize(smooth.position, field, v_max, a_max,
                                             config_.clearance.bound() + config_.optimizer.target_margin);
      if (result.optimizer.failed) {
        attempt = "optimiser failed (" + result.optimizer.message + ")";
        cause = FallbackCause::kOptimizerFailed;
      } else if (const double off = deviation(smooth.position, route, &trouble);
                 off > config_.trajectory.max_deviation) {
        std::ostringstream s;
        s << "optimised trajectory strays " << std::fixed << std::setprecision(2) << off
          << " m from the path";
        attempt = s.str();
        cause = FallbackCause::kStrays;
      } else if (finish(smooth, times, split ? split->yaws : yaws, v_max, field, result)) {
        result.ok = true;
        result.trajectory = std::move(smooth);
        return true;
      } else {
        attempt = "optimised trajectory too close to an obstacle: " + describe(result.clearance);
        cause = FallbackCause::kTooClose;
        trouble = result.clearance.violation_point;
      }
      return false;
    };
    if (optimised(v_max, nullptr)) return result;
    // The full-speed attempt says why the vehicle does not fly it.
    why = attempt;
    result.cause = cause;
    // The trouble is usually one place (a doorway the turned body passes only square, a corner
    // cut too wide): the curve is optimised again at the fallback's cruise speed within
    // slow_zone_radius of it, at full speed elsewhere. Slowing the whole path for it had flown
    // a 27 s tour leg across env3 at half speed for one door.
    const TrajectoryConfig& tc = config_.trajectory;
    if (v_fallback < v_max && cause != FallbackCause::kOptimizerFailed && tc.slow_zone_radius > 0) {
      SlowZones zones;
      for (int k = 0; k < tc.slow_zone_tries; ++k) {
        zones.add(trouble, tc.slow_zone_radius);
        const SlowZones::Split split = zones.split(polyline, yaws, v_fallback, v_max);
        if (optimised(v_max, &split)) {
          result.slowed = true;
          result.slow_zones = static_cast<int>(zones.zones.size());
          std::ostringstream s;
          const SlowZones::Zone& z = zones.zones.back();
          s << "optimised at " << std::setprecision(3) << v_fallback << " m/s within " << z.radius << " m of "
            << zones.zones.size() << " place(s), the last (" << z.centre.x() << ", " << z.centre.y() << ", "
            << z.centre.z() << "): " << why;
          result.reason = s.str();
          return result;
        }
        if (cause == FallbackCause::kOptimizerFailed) break;
      }
    }
    // Tried once more at the fallback's cruise speed: a corner is cut by about v²/a, so a quarter
    // as far at half the speed, and the curve still does not stop at every waypoint as the
    // fallback does.
    if (v_fallback < v_max && result.cause != FallbackCause::kOptimizerFailed &&
        optimised(v_fallback, nullptr)) {
      result.slowed = true;
      std::ostringstream s;
      s << "optimised at " << std::setprecision(3) << v_fallback << " m/s: " << why;
      result.reason = s.str();
      return result;
    }
  } else {
    why = "optimiser disabled";
    result.cause = FallbackCause::kOptimizerOff;
  }

  // The fallback brakes from the vehicle's velocity first, as the vehicle will. Where that ray
  // is too close to an obstacle, the fallback at rest on the path is still the best reference:
  // the tracker then brakes as hard as the vehicle can, and no reference can stop it sooner.
  const auto fallback = [&](const Eigen::Vector3d& v) {
    FallbackSpline fb = make_fallback_spline(polyline, v, v_fallback, a_max, dt);
    Trajectory safe;
    safe.optimized = false;
    safe.position = std::move(fb.spline);
    if (!finish(safe, fb.point_times, yaws, v_max, field, result)) return false;
    result.ok = true;
    result.trajectory = std::move(safe);
    result.reason = "fallback: " + why;
    return true;
  };
  if (fallback(v0) || (!v0.isZero() && fallback(Eigen::Vector3d::Zero()))) return result;
  result.reason = "no safe trajectory: " + why + "; the path itself: " + describe(result.clearance);
  return result;
}

}  // namespace semx::controller
