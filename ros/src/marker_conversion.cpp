#include "semx/ros/marker_conversion.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "semx/runtime/semantic_classes.hpp"

namespace semx::rosbridge {

namespace {

constexpr const char* kNodes = "roadmap/nodes";
constexpr const char* kEdges = "roadmap/edges";
constexpr const char* kPath = "roadmap/path";
constexpr const char* kRegions = "regions";
constexpr const char* kLabels = "regions/labels";
constexpr float kActiveAlpha = 0.3f;
constexpr float kInactiveAlpha = 0.12f;

msg::Marker base_marker(const std::string& frame, int64_t stamp_ns, const char* ns, int32_t id, int32_t type) {
  msg::Marker m;
  m.header.frame_id = frame;
  m.header.stamp_ns = stamp_ns;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = msg::Marker::ADD;
  return m;
}

msg::Marker delete_all(const std::string& frame, int64_t stamp_ns) {
  msg::Marker m = base_marker(frame, stamp_ns, "", 0, msg::Marker::SPHERE);
  m.action = msg::Marker::DELETEALL;
  return m;
}

const msg::Marker* find(const msg::MarkerArray& a, const std::string& ns, int32_t type) {
  for (const auto& m : a.markers) {
    if (m.ns == ns && m.type == type && m.action == msg::Marker::ADD) return &m;
  }
  return nullptr;
}

using PointKey = std::tuple<double, double, double>;
PointKey key_of(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

msg::Color score_color(double score, double lo, double hi) {
  double t = hi > lo ? (score - lo) / (hi - lo) : 1.0;
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0);
  // Three stops of viridis: dark blue, green, yellow.
  const double stops[3][3] = {{0.267, 0.005, 0.329}, {0.128, 0.567, 0.551}, {0.993, 0.906, 0.144}};
  const double s = t * 2.0;
  const int i = std::min(1, static_cast<int>(s));
  const double f = s - i;
  msg::Color c;
  c.r = static_cast<float>(stops[i][0] + f * (stops[i + 1][0] - stops[i][0]));
  c.g = static_cast<float>(stops[i][1] + f * (stops[i + 1][1] - stops[i][1]));
  c.b = static_cast<float>(stops[i][2] + f * (stops[i + 1][2] - stops[i][2]));
  c.a = 1.0f;
  return c;
}

msg::MarkerArray roadmap_markers(const Roadmap& r, const std::string& frame, int64_t stamp_ns) {
  msg::MarkerArray a;
  a.markers.push_back(delete_all(frame, stamp_ns));
  if (r.nodes.empty()) return a;

  double lo = r.nodes.front().score, hi = lo;
  for (const auto& n : r.nodes) {
    if (!std::isfinite(n.score)) continue;
    lo = std::min(lo, n.score);
    hi = std::max(hi, n.score);
  }
  msg::Marker nodes = base_marker(frame, stamp_ns, kNodes, 0, msg::Marker::SPHERE_LIST);
  nodes.scale = Eigen::Vector3d::Constant(0.08);
  msg::Marker path = base_marker(frame, stamp_ns, kPath, 0, msg::Marker::SPHERE_LIST);
  path.scale = Eigen::Vector3d::Constant(0.16);
  path.color = {1.0f, 0.45f, 0.0f, 0.9f};
  std::map<int64_t, const RoadmapNode*> by_id;
  for (const auto& n : r.nodes) {
    nodes.points.push_back(n.position);
    nodes.colors.push_back(score_color(n.score, lo, hi));
    if (n.flags & (RoadmapNode::kOnPath | RoadmapNode::kGoal)) path.points.push_back(n.position);
    by_id[n.id] = &n;
  }
  a.markers.push_back(std::move(nodes));

  msg::Marker edges = base_marker(frame, stamp_ns, kEdges, 0, msg::Marker::LINE_LIST);
  edges.scale = Eigen::Vector3d(0.01, 0, 0);
  edges.color = {0.55f, 0.55f, 0.6f, 0.25f};
  for (const auto& [from, to] : r.edges) {
    auto f = by_id.find(from), t = by_id.find(to);
    if (f == by_id.end() || t == by_id.end()) continue;
    edges.points.push_back(f->second->position);
    edges.points.push_back(t->second->position);
  }
  if (!edges.points.empty()) a.markers.push_back(std::move(edges));
  if (!path.points.empty()) a.markers.push_back(std::move(path));
  return a;
}

msg::MarkerArray region_markers(const std::vector<Region>& regions, const std::string& frame, int64_t stamp_ns) {
  msg::MarkerArray a;
  a.markers.push_back(delete_all(frame, stamp_ns));
  for (const auto& reg : regions) {
    const int32_t id = static_cast<int32_t>(reg.id);
    msg::Marker s = base_marker(frame, stamp_ns, kRegions, id, msg::Marker::SPHERE);
    s.pose.position = reg.centroid;
    s.scale = Eigen::Vector3d::Constant(2.0 * reg.radius);
    msg::Color c{0.8f, 0.8f, 0.8f, 1.0f};
    if (auto cls = runtime::class_from_id(reg.class_id)) {
      const auto& rgb = runtime::class_info(*cls).rgb;
      c = {rgb[0] / 255.0f, rgb[1] / 255.0f, rgb[2] / 255.0f, 1.0f};
    }
    c.a = reg.active ? kActiveAlpha : kInactiveAlpha;
    s.color = c;
    a.markers.push_back(std::move(s));

    msg::Marker t = base_marker(frame, stamp_ns, kLabels, id, msg::Marker::TEXT_VIEW_FACING);
    t.pose.position = reg.centroid + Eigen::Vector3d(0, 0, reg.radius + 0.1);
    t.scale = Eigen::Vector3d(0, 0, 0.2);
    t.color = {1.0f, 1.0f, 1.0f, 1.0f};
    t.text = reg.label + " #" + std::to_string(reg.id);
    a.markers.push_back(std::move(t));
  }
  return a;
}

bool roadmap_from_markers(const msg::MarkerArray& a, Roadmap& out) {
  if (a.markers.empty() || a.markers.front().action != msg::Marker::DELETEALL) return false;
  Roadmap r;
  const msg::Marker* nodes = find(a, kNodes, msg::Marker::SPHERE_LIST);
  if (!nodes) {
    out = r;
    return a.markers.size() == 1;
  }
  std::map<PointKey, std::size_t> index;
  for (std::size_t i = 0; i < nodes->points.size(); ++i) {
    RoadmapNode n;
    n.id = static_cast<int64_t>(i);
    n.position = nodes->points[i];
    index.emplace(key_of(n.position), i);
    r.nodes.push_back(n);
  }
  if (const msg::Marker* edges = find(a, kEdges, msg::Marker::LINE_LIST)) {
    if (edges->points.size() % 2 != 0) return false;
    for (std::size_t i = 0; i < edges->points.size(); i += 2) {
      auto f = index.find(key_of(edges->points[i])), t = index.find(key_of(edges->points[i + 1]));
      if (f == index.end() || t == index.end()) return false;
      r.edges.emplace_back(static_cast<int64_t>(f->second), static_cast<int64_t>(t->second));
    }
  }
  if (const msg::Marker* path = find(a, kPath, msg::Marker::SPHERE_LIST)) {
    for (const auto& p : path->points) {
      auto it = index.find(key_of(p));
      if (it == index.end()) return false;
      r.nodes[it->second].flags |= RoadmapNode::kOnPath;
    }
  }
  out = std::move(r);
  return true;
}

bool regions_from_markers(const msg::MarkerArray& a, std::vector<Region>& out) {
  if (a.markers.empty() || a.markers.front().action != msg::Marker::DELETEALL) return false;
  std::map<int32_t, std::string> labels;
  for (const auto& m : a.markers) {
    if (m.ns == kLabels && m.type == msg::Marker::TEXT_VIEW_FACING) labels[m.id] = m.text;
  }
  std::vector<Region> regions;
  for (const auto& m : a.markers) {
    if (m.ns != kRegions || m.type != msg::Marker::SPHERE) continue;
    Region r;
    r.id = m.id;
    r.centroid = m.pose.position;
    r.radius = 0.5 * m.scale.x();
    r.active = m.color.a > 0.5f * (kActiveAlpha + kInactiveAlpha);
    auto l = labels.find(m.id);
    if (l == labels.end()) return false;
    const std::string suffix = " #" + std::to_string(m.id);
    if (l->second.size() < suffix.size() || l->second.compare(l->second.size() - suffix.size(), suffix.size(), suffix) != 0) {
      return false;
    }
    r.label = l->second.substr(0, l->second.size() - suffix.size());
    if (auto cls = runtime::class_from_name(r.label)) r.class_id = static_cast<int>(*cls);
    regions.push_back(std::move(r));
  }
  out = std::move(regions);
  return true;
}

}  // namespace semx::rosbridge
