#include "semx/viewer/top_down_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <unordered_map>

namespace semx::viewer {

namespace {

evaluator::Rgb lerp(evaluator::Rgb a, evaluator::Rgb b, double t) {
  auto mix = [t](uint8_t x, uint8_t y) {
    return static_cast<uint8_t>(std::lround(std::clamp(x + (y - x) * t, 0.0, 255.0)));
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

// The ground truth is built only for voxel sizes a real map has: a bogus resolution on the wire
// must not make the viewer allocate a world at 1 mm.
constexpr double kMinGroundTruthRes = 0.02;
constexpr double kMaxGroundTruthRes = 1.0;

}  // namespace

std::string planner_state_name(int state) {
  static const char* kNames[] = {"INIT", "PLANNING", "EXECUTING", "RECOVERING", "DONE", "FAILED"};
  if (state >= 0 && state < 6) return kNames[state];
  return "state " + std::to_string(state);
}

TopDownView::TopDownView(TopDownViewOptions options) : options_(std::move(options)) {
  options_.trail_step_m = std::max(0.0, options_.trail_step_m);
  options_.limits.max_trail_points = std::max<size_t>(options_.limits.max_trail_points, 16);
}

void TopDownView::set_world(simulator::World world) {
  world_ = std::move(world);
  gt_.reset();
}

bool TopDownView::plausible(const Eigen::Vector3d& p) const {
  const double m = options_.limits.max_coord_m;
  return p.allFinite() && std::abs(p.x()) <= m && std::abs(p.y()) <= m && std::abs(p.z()) <= m;
}

std::string TopDownView::clean_label(const std::string& s) const {
  std::string out;
  for (const char c : s) {
    if (out.size() >= options_.limits.max_label_chars) break;
    out.push_back(c >= 32 && c < 127 ? c : '?');
  }
  return out;
}

bool TopDownView::add_pose(int64_t utime, const Eigen::Vector3d& position, const Eigen::Vector4d& q) {
  if (!plausible(position)) {
    ++skipped_;
    return false;
  }
  const double n = q.norm();
  if (std::isfinite(n) && n > 1e-6) {
    const Eigen::Vector4d u = q / n;  // w, x, y, z
    const double w = u[0], x = u[1], y = u[2], z = u[3];
    yaw_ = std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  }
  pose_position_ = position;
  last_pose_utime_ = utime;
  if (trail_.empty() || (trail_.back() - position).head<2>().norm() >= options_.trail_step_m ||
      std::abs(trail_.back().z() - position.z()) >= options_.trail_step_m) {
    trail_.push_back(position);
  }
  if (trail_.size() > options_.limits.max_trail_points) {
    // Thin the whole trail rather than forget its start: a long run keeps its shape.
    std::vector<Eigen::Vector3d> thin;
    thin.reserve(trail_.size() / 2 + 2);
    for (size_t i = 0; i < trail_.size(); i += 2) thin.push_back(trail_[i]);
    if ((trail_.size() - 1) % 2 != 0) thin.push_back(trail_.back());
    trail_ = std::move(thin);
  }
  return true;
}

bool TopDownView::set_roadmap(Roadmap roadmap) {
  Roadmap kept;
  kept.utime = roadmap.utime;
  kept.iteration = roadmap.iteration;
  std::unordered_map<int64_t, size_t> index;
  for (const RoadmapNode& n : roadmap.nodes) {
    if (kept.nodes.size() >= options_.limits.max_nodes || !plausible(n.position) || index.count(n.id)) {
      ++skipped_;
      continue;
    }
    index.emplace(n.id, kept.nodes.size());
    kept.nodes.push_back(n);
  }
  for (const auto& e : roadmap.edges) {
    if (kept.edges.size() >= options_.limits.max_edges || !index.count(e.first) || !index.count(e.second)) {
      ++skipped_;
      continue;
    }
    kept.edges.push_back(e);
  }
  const bool usable = kept.nodes.size() > 0 || roadmap.nodes.empty();
  roadmap_ = std::move(kept);
  return usable;
}

bool TopDownView::set_regions(std::vector<Region> regions) {
  std::vector<Region> kept;
  for (Region& r : regions) {
    if (kept.size() >= options_.limits.max_regions || !plausible(r.centroid) || !std::isfinite(r.radius) ||
        r.radius < 0) {
      ++skipped_;
      continue;
    }
    r.radius = std::min(r.radius, options_.limits.max_radius_m);
    r.label = clean_label(r.label);
    if (!std::isfinite(r.weight)) r.weight = 0;
    kept.push_back(std::move(r));
  }
  const bool usable = !kept.empty() || regions.empty();
  regions_ = std::move(kept);
  return usable;
}

bool TopDownView::set_path(std::vector<Eigen::Vector3d> waypoints) {
  std::vector<Eigen::Vector3d> kept;
  for (const auto& p : waypoints) {
    if (kept.size() >= options_.limits.max_path_points || !plausible(p)) {
      ++skipped_;
      continue;
    }
    kept.push_back(p);
  }
  const bool usable = !kept.empty() || waypoints.empty();
  path_ = std::move(kept);
  return usable;
}

std::vector<Eigen::Vector3d> sample_curve(const TrajectoryCurve& c, double step_s) {
  const auto& q = c.control_points;
  std::vector<Eigen::Vector3d> out;
  if (c.degree != 3) return q;  // not a cubic: its control polygon, which the curve stays near
  if (q.size() < 4 || !(c.knot_interval > 0) || !(step_s > 0)) return out;
  // Segment i spans [i·dt, (i+1)·dt) on control points i..i+3 (uniform cubic B-spline basis).
  const size_t segments = q.size() - 3;
  const int per_segment = std::max(1, static_cast<int>(std::ceil(c.knot_interval / step_s)));
  for (size_t i = 0; i < segments; ++i) {
    for (int k = 0; k < per_segment || (i + 1 == segments && k == per_segment); ++k) {
      const double u = static_cast<double>(k) / per_segment, u2 = u * u, u3 = u2 * u;
      const double b0 = (1 - 3 * u + 3 * u2 - u3) / 6, b1 = (4 - 6 * u2 + 3 * u3) / 6,
                   b2 = (1 + 3 * u + 3 * u2 - 3 * u3) / 6, b3 = u3 / 6;
      out.push_back(b0 * q[i] + b1 * q[i + 1] + b2 * q[i + 2] + b3 * q[i + 3]);
    }
  }
  return out;
}

bool TopDownView::set_trajectory(const TrajectoryCurve& curve) {
  // Control points off the wire: the same sanity as a path, before any arithmetic on them.
  TrajectoryCurve c = curve;
  c.control_points.clear();
  for (const auto& p : curve.control_points) {
    if (c.control_points.size() >= options_.limits.max_path_points || !plausible(p)) {
      ++skipped_;
      continue;
    }
    c.control_points.push_back(p);
  }
  if (!std::isfinite(c.knot_interval) || c.knot_interval <= 0 || c.knot_interval > 10) c.degree = 0;
  trajectory_ = sample_curve(c);
  if (trajectory_.size() > options_.limits.max_path_points)
    trajectory_.resize(options_.limits.max_path_points);
  trajectory_optimized_ = curve.optimized;
  return !trajectory_.empty() || curve.control_points.empty();
}

void TopDownView::set_planner(PlannerInfo info) {
  info.planner = clean_label(info.planner);
  // Reasons are sentences: allow a longer text than labels.
  std::string reason;
  for (const char c : info.reason) {
    if (reason.size() >= 80) break;
    reason.push_back(c >= 32 && c < 127 ? c : '?');
  }
  info.reason = std::move(reason);
  planner_ = std::move(info);
}

void TopDownView::clear_run() {
  trail_.clear();
  pose_position_.reset();
  last_pose_utime_ = -1;
  roadmap_ = Roadmap{};
  regions_.clear();
  path_.clear();
  trajectory_.clear();
  planner_ = PlannerInfo{};
}

std::string TopDownView::header(const map::StateGrid* grid) const {
  double known_m3 = 0;
  if (grid) {
    const double r = grid->resolution();
    known_m3 = static_cast<double>(grid->known_voxels()) * r * r * r;
  }
  char b[160];
  std::snprintf(b, sizeof b, "t %.1f s   known %.1f m3", static_cast<double>(utime_) * 1e-6, known_m3);
  std::string s = b;
  if (planner_.state >= 0 || !planner_.planner.empty()) {
    s += "   " + (planner_.planner.empty() ? std::string("planner") : planner_.planner) + " " +
         planner_state_name(planner_.state);
    if (planner_.iteration > 0) s += " #" + std::to_string(planner_.iteration);
    if (!planner_.reason.empty()) s += ": " + planner_.reason;
  }
  return s;
}

void TopDownView::include(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  if (!have_area_) {
    area_lo_ = lo;
    area_hi_ = hi;
    have_area_ = true;
    return;
  }
  area_lo_ = area_lo_.cwiseMin(lo);
  area_hi_ = area_hi_.cwiseMax(hi);
}

evaluator::MapView TopDownView::update_view(const map::StateGrid* grid) {
  const double res = grid ? grid->resolution() : empty_grid_.resolution();
  evaluator::MapView v;
  if (world_) v = evaluator::MapView::of_world(*world_);
  if (options_.z_band) {
    v.z_lo = options_.z_band->first;
    v.z_hi = std::max(v.z_lo, options_.z_band->second);
  } else if (!world_) {
    v.z_lo = 0.15;
    v.z_hi = 2.2;
  }
  Eigen::Vector2d lo, hi;
  if (options_.area) {
    lo = options_.area->first;
    hi = options_.area->second;
  } else if (world_) {
    lo = v.lo;
    hi = v.hi;
  } else {
    // Everything seen so far, padded and snapped, grown into the remembered area.
    bool any = false;
    Eigen::Vector2d clo(0, 0), chi(0, 0);
    auto add = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      if (!(a.allFinite() && b.allFinite())) return;
      clo = any ? clo.cwiseMin(a) : a;
      chi = any ? chi.cwiseMax(b) : b;
      any = true;
    };
    if (grid && !grid->known_bounds().empty()) {
      const auto& kb = grid->known_bounds();
      const Eigen::Vector2d a(kb.min.x * res, kb.min.y * res), b((kb.max.x + 1) * res, (kb.max.y + 1) * res);
      const double m = options_.limits.max_coord_m;
      add(a.cwiseMax(-m), b.cwiseMin(m));
    }
    for (const auto& p : trail_) add(p.head<2>(), p.head<2>());
    if (pose_position_) add(pose_position_->head<2>(), pose_position_->head<2>());
    for (const auto& n : roadmap_.nodes) add(n.position.head<2>(), n.position.head<2>());
    for (const auto& p : path_) add(p.head<2>(), p.head<2>());
    for (const auto& r : regions_) {
      const Eigen::Vector2d c = r.centroid.head<2>(), d(r.radius, r.radius);
      add(c - d, c + d);
    }
    if (any) {
      const double s = std::max(options_.snap_m, res);
      const Eigen::Vector2d m(options_.margin_m, options_.margin_m);
      const Eigen::Vector2d a = ((clo - m) / s).array().floor() * s;
      const Eigen::Vector2d b = ((chi + m) / s).array().ceil() * s;
      include(a, b);
    }
    // Nothing seen yet: a default square, not remembered (the first real content replaces it).
    lo = have_area_ ? area_lo_ : Eigen::Vector2d(-5, -5);
    hi = have_area_ ? area_hi_ : Eigen::Vector2d(5, 5);
  }
  if (!(lo.allFinite() && hi.allFinite())) lo = {-5, -5}, hi = {5, 5};
  hi = hi.cwiseMax(lo + Eigen::Vector2d::Constant(res));
  // Never a picture larger than the limits: a far-away item (a bogus voxel, a stray node) then
  // costs the view its edges, not the process its memory. The window follows the vehicle.
  const double side = std::min(options_.limits.max_extent_m, options_.limits.max_side_px * res);
  const Eigen::Vector2d centre =
      pose_position_ ? Eigen::Vector2d(pose_position_->head<2>()) : 0.5 * (lo + hi);
  for (int i = 0; i < 2; ++i) {
    if (hi[i] - lo[i] <= side) continue;
    const double c = std::clamp(centre[i], lo[i] + side / 2, hi[i] - side / 2);
    lo[i] = c - side / 2;
    hi[i] = c + side / 2;
  }
  v.lo = lo;
  v.hi = hi;
  return v;
}

evaluator::Rgb TopDownView::score_color(double t) {
  const evaluator::Rgb low{110, 60, 190}, mid{240, 150, 30}, high{215, 20, 40};
  if (!std::isfinite(t)) return {150, 150, 150};
  t = std::clamp(t, 0.0, 1.0);
  return t < 0.5 ? lerp(low, mid, 2 * t) : lerp(mid, high, 2 * t - 1);
}

evaluator::Rgb TopDownView::edge_color(double t) {
  if (!std::isfinite(t)) return {200, 200, 200};
  return lerp(score_color(t), {255, 255, 255}, 0.45);
}

evaluator::Rgb TopDownView::region_color(int class_id) { return evaluator::palette(class_id); }

std::vector<double> TopDownView::normalized_scores() const {
  // By rank, not by value: scores are heavy-tailed (a few nodes near large unknown regions), and
  // a linear scale would paint all but those few the lowest colour.
  const auto& nodes = roadmap_.nodes;
  std::vector<size_t> order;
  order.reserve(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (std::isfinite(nodes[i].score)) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return nodes[a].score < nodes[b].score; });
  std::vector<double> t(nodes.size(), NAN);
  const size_t m = order.size();
  for (size_t lo = 0; lo < m;) {
    size_t hi = lo;
    while (hi + 1 < m && nodes[order[hi + 1]].score == nodes[order[lo]].score) ++hi;
    // Equal scores share their mean rank, so equal scores get equal colours.
    const double rank = 0.5 * static_cast<double>(lo + hi);
    for (size_t k = lo; k <= hi; ++k) t[order[k]] = m > 1 ? rank / static_cast<double>(m - 1) : 0.5;
    lo = hi + 1;
  }
  return t;
}

evaluator::MapPicture TopDownView::picture(const map::StateGrid* grid) {
  const map::StateGrid& g = grid ? *grid : empty_grid_;
  const double res = g.resolution();
  const evaluator::MapView v = update_view(grid);

  evaluator::MapPictureOptions o;
  o.title = header(grid);
  o.legend = options_.legend;
  o.unmapped_wall = options_.walls;
  const double cols = std::max((v.hi.x() - v.lo.x()) / res, (v.hi.y() - v.lo.y()) / res) + 1;
  int ppc = options_.scale_px_per_m > 0 && std::isfinite(options_.scale_px_per_m)
                ? static_cast<int>(std::lround(std::min(options_.scale_px_per_m * res, 1000.0)))
                : static_cast<int>(options_.fit_side_px / cols);
  ppc = std::clamp(ppc, 1, std::max(1, static_cast<int>(options_.limits.max_side_px / cols)));
  o.pixels_per_column = ppc;
  evaluator::MapPicture pic(g, v, o);

  if (world_ && res >= kMinGroundTruthRes && res <= kMaxGroundTruthRes) {
    if (!gt_ || std::abs(gt_->resolution() - res) > 1e-9) gt_.emplace(*world_, res);
    pic.underlay_ground_truth(*gt_);
  }

  // Regions under everything else: translucent discs while they attract, rings once observed.
  std::set<int> classes;
  for (const Region& r : regions_) {
    char b[64];
    std::snprintf(b, sizeof b, " %.2g", r.weight);
    const std::string label = (r.label.empty() ? "class " + std::to_string(r.class_id) : r.label) + b;
    pic.add_circle(r.centroid.head<2>(), r.radius, region_color(r.class_id), label, r.active, 2);
    classes.insert(r.class_id);
  }

  // Roadmap edges, coloured by their ends' scores.
  const std::vector<double> t = normalized_scores();
  std::unordered_map<int64_t, size_t> index;
  for (size_t i = 0; i < roadmap_.nodes.size(); ++i) index.emplace(roadmap_.nodes[i].id, i);
  for (const auto& e : roadmap_.edges) {
    const auto a = index.find(e.first), b = index.find(e.second);
    if (a == index.end() || b == index.end()) continue;
    const double ta = t[a->second], tb = t[b->second];
    const double te = std::isfinite(ta) && std::isfinite(tb) ? 0.5 * (ta + tb) : NAN;
    pic.add_segment(roadmap_.nodes[a->second].position.head<2>(),
                    roadmap_.nodes[b->second].position.head<2>(), edge_color(te), 1);
  }

  pic.add_polyline(trail_, options_.trail, 2);
  pic.add_polyline(path_, options_.path, 2);
  pic.add_polyline(trajectory_, trajectory_optimized_ ? options_.trajectory : options_.fallback_trajectory,
                   2);

  // Nodes over the lines; the goal last so it stays visible.
  const RoadmapNode* goal = nullptr;
  for (size_t i = 0; i < roadmap_.nodes.size(); ++i) {
    const RoadmapNode& n = roadmap_.nodes[i];
    if ((n.flags & RoadmapNode::kGoal) && !goal) goal = &n;
    pic.add_marker(n.position.head<2>(), std::isfinite(t[i]) ? score_color(t[i]) : options_.no_score, "", 3);
  }
  // The path usually ends at the goal: its dot first, so the goal's covers it.
  if (!path_.empty()) pic.add_marker(path_.back().head<2>(), options_.path, goal ? "" : "path end", 4);
  if (goal) pic.add_marker(goal->position.head<2>(), options_.goal, "goal", 6);

  if (pose_position_) {
    const double px_per_m = ppc / res;
    const double len = std::max(options_.arrow_length_m, 16.0 / px_per_m);
    const Eigen::Vector2d p = pose_position_->head<2>();
    pic.add_arrow(p, p + len * Eigen::Vector2d(std::cos(yaw_), std::sin(yaw_)), options_.vehicle, 3);
    pic.add_marker(p, options_.vehicle, "", 4);
  }

  pic.add_legend("trail", options_.trail);
  pic.add_legend("path", options_.path);
  if (!trajectory_.empty()) {
    pic.add_legend(trajectory_optimized_ ? "trajectory (optimised)" : "trajectory (fallback)",
                   trajectory_optimized_ ? options_.trajectory : options_.fallback_trajectory);
  }
  pic.add_legend("vehicle", options_.vehicle);
  if (!roadmap_.nodes.empty()) {
    pic.add_legend("node: low score", score_color(0));
    pic.add_legend("node: high score", score_color(1));
    pic.add_legend("roadmap edge", edge_color(0.5));
    pic.add_legend("goal", options_.goal);
  }
  int shown = 0;
  for (const int c : classes) {
    if (++shown > 8) break;
    std::string name;
    for (const Region& r : regions_) {
      if (r.class_id == c && !r.label.empty()) {
        name = r.label;
        break;
      }
    }
    pic.add_legend("region: " + (name.empty() ? std::to_string(c) : name), region_color(c));
  }
  return pic;
}

FrameSchedule::FrameSchedule(double period_s)
    : period_us_(std::max<int64_t>(
          1, static_cast<int64_t>(
                 std::llround(std::clamp(std::isfinite(period_s) ? period_s : 1.0, 1e-6, 1e6) * 1e6)))) {}

int64_t FrameSchedule::due(int64_t utime) {
  if (utime < 0) return -1;
  const int64_t k = utime / period_us_;
  if (k <= last_) return -1;
  last_ = k;
  return k;
}

std::string frame_file_name(int64_t index) {
  char b[48];
  std::snprintf(b, sizeof b, "frame_%06lld.png", static_cast<long long>(index));
  return b;
}

}  // namespace semx::viewer
