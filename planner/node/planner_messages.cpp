#include "planner_messages.hpp"

#include <cmath>

namespace semx::planner {

semx::path_t to_message(const PlannedPath& p, int64_t utime) {
  semx::path_t m{};
  m.utime = utime;
  m.plan_id = p.plan_id;
  m.num_waypoints = static_cast<int32_t>(p.waypoints.size());
  for (size_t i = 0; i < p.waypoints.size(); ++i) {
    m.waypoints.push_back({p.waypoints[i].x(), p.waypoints[i].y(), p.waypoints[i].z()});
    m.yaws.push_back(i < p.yaws.size() ? p.yaws[i] : 0.0);
  }
  m.max_speed = 0.0;
  return m;
}

semx::roadmap_t to_message(const RoadmapView& v, int64_t utime) {
  semx::roadmap_t m{};
  m.utime = utime;
  m.iteration = v.iteration;
  m.num_nodes = static_cast<int32_t>(v.nodes.size());
  for (const RoadmapView::Node& n : v.nodes) {
    semx::roadmap_node_t o{};
    o.id = n.id;
    for (int a = 0; a < 3; ++a) o.position[a] = n.position[a];
    o.yaw = n.yaw;
    o.gain = n.gain;
    o.reward = n.reward;
    o.cost = n.cost;
    o.score = n.score;
    o.flags = n.flags;
    m.nodes.push_back(o);
  }
  m.num_edges = static_cast<int32_t>(v.edges.size());
  for (const auto& e : v.edges) {
    m.edge_from.push_back(e.first);
    m.edge_to.push_back(e.second);
  }
  return m;
}

semx::planner_status_t to_message(const StatusReport& s, int64_t utime) {
  semx::planner_status_t m{};
  m.utime = utime;
  m.planner = s.planner;
  m.state = static_cast<int8_t>(s.state);
  m.reason = s.reason;
  m.iteration = s.iteration;
  m.num_nodes = s.num_nodes;
  m.num_edges = s.num_edges;
  for (int a = 0; a < 3; ++a) m.goal[a] = s.goal[a];
  m.best_gain = s.best_gain;
  m.best_reward = s.best_reward;
  m.best_score = s.best_score;
  m.sample_ms = s.counters.sample_ms;
  m.connect_ms = s.counters.connect_ms;
  m.gain_ms = s.counters.gain_ms;
  m.search_ms = s.counters.search_ms;
  m.total_ms = s.counters.total_ms;
  m.charged_s = s.charged_s;
  return m;
}

VehiclePose to_pose(const semx::odometry_t& m) {
  VehiclePose p;
  p.utime = m.utime;
  p.position = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
  const double w = m.orientation[0], x = m.orientation[1], y = m.orientation[2], z = m.orientation[3];
  p.yaw = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return p;
}

std::vector<SemanticRegion> to_regions(const semx::semantic_regions_t& m) {
  std::vector<SemanticRegion> out;
  out.reserve(m.regions.size());
  for (const semx::semantic_region_t& r : m.regions) {
    SemanticRegion s;
    s.id = r.id;
    s.class_id = r.class_id;
    s.centroid = Eigen::Vector3d(r.centroid[0], r.centroid[1], r.centroid[2]);
    s.weight = r.weight;
    s.radius = r.radius;
    s.active = r.active != 0;
    s.extent = Eigen::Vector3d(r.extent[0], r.extent[1], r.extent[2]);
    out.push_back(s);
  }
  return out;
}

bool accept_odometry(const semx::odometry_t& m) {
  double q2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(m.orientation[i])) return false;
    q2 += m.orientation[i] * m.orientation[i];
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(m.position[i]) || std::abs(m.position[i]) > 1e5) return false;
  }
  return std::abs(std::sqrt(q2) - 1.0) <= 1e-3;
}

bool accept_regions(const semx::semantic_regions_t& m) {
  if (m.num_regions < 0 || static_cast<size_t>(m.num_regions) != m.regions.size()) return false;
  for (const semx::semantic_region_t& r : m.regions) {
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(r.centroid[i])) return false;
    if (!std::isfinite(r.weight) || !std::isfinite(r.radius)) return false;
  }
  return true;
}

bool accept_controller_status(const semx::controller_status_t& m) {
  return m.state >= semx::controller_status_t::IDLE && m.state <= semx::controller_status_t::REJECTED;
}

}  // namespace semx::planner
