#include "semx/runtime/roadmap_messages.hpp"

#include <algorithm>

namespace semx::runtime {

namespace {
Eigen::Vector3d vec3(const double* v) { return {v[0], v[1], v[2]}; }
}  // namespace

core::Roadmap roadmap_from(const semx::roadmap_t& m) {
  core::Roadmap r;
  r.utime = m.utime;
  r.iteration = m.iteration;
  r.nodes.reserve(m.nodes.size());
  for (const auto& n : m.nodes) {
    core::RoadmapNode x;
    x.id = n.id;
    x.position = vec3(n.position);
    x.yaw = n.yaw;
    x.gain = n.gain;
    x.reward = n.reward;
    x.cost = n.cost;
    x.score = n.score;
    x.flags = n.flags;
    r.nodes.push_back(x);
  }
  // The wire validator makes both arrays num_edges long; min() guards a hand-built message.
  const size_t ne = std::min(m.edge_from.size(), m.edge_to.size());
  r.edges.reserve(ne);
  for (size_t i = 0; i < ne; ++i) r.edges.emplace_back(m.edge_from[i], m.edge_to[i]);
  return r;
}

std::vector<core::Region> regions_from(const semx::semantic_regions_t& m) {
  std::vector<core::Region> out;
  out.reserve(m.regions.size());
  for (const auto& s : m.regions) {
    core::Region r;
    r.id = s.id;
    r.class_id = s.class_id;
    r.label = s.label;
    r.instance = s.instance;
    r.centroid = vec3(s.centroid);
    r.weight = s.weight;
    r.radius = s.radius;
    r.extent = vec3(s.extent);
    r.confidence = s.confidence;
    r.observations = s.observations;
    r.observed_fraction = s.observed_fraction;
    r.active = s.active;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace semx::runtime
