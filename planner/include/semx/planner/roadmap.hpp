// The roadmap: an undirected graph of viewpoints kept across planning cycles (DEP's incremental
// PRM), with a spatial hash for neighbour queries and Dijkstra for travel distances.
//
// Node ids are indices that are never reused, so an id in a message or a path always means the
// same node; removed nodes stay as dead slots. Every query orders its results by (distance, id),
// so the graph a seed builds does not depend on hash-table iteration order.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "semx/planner/gain_evaluator.hpp"

namespace semx::planner {

struct RoadmapEdge {
  int64_t to = -1;
  double length = 0.0;
};

struct RoadmapNode {
  int64_t id = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  bool alive = false;
  std::vector<RoadmapEdge> edges;
  NodeGain gain;                   // cached; gain.valid false until evaluated
  bool gain_stale = true;          // map changed within sensor range since the evaluation
  int64_t gain_cycle = -1;         // cycle of the last evaluation
  int64_t blacklisted_until = -1;  // cycle until which it is not a goal (controller rejected it)
  // Only passage_free (a doorway narrower than the node clearance allows): a waypoint, never a
  // goal (the vehicle would hover where one voxel of map noise puts it below the controller's
  // bound).
  bool passage = false;
};

class Roadmap {
 public:
  // cell_size: edge of the spatial hash cells (about the largest query radius).
  explicit Roadmap(double cell_size = 2.5);

  int64_t add_node(const Eigen::Vector3d& p);
  void remove_node(int64_t id);  // and its edges
  // Moves a node (its edges keep their old lengths: the caller re-checks and re-measures them).
  void move_node(int64_t id, const Eigen::Vector3d& p);
  bool alive(int64_t id) const {
    return id >= 0 && id < static_cast<int64_t>(nodes_.size()) && nodes_[id].alive;
  }
  RoadmapNode& node(int64_t id) { return nodes_[static_cast<size_t>(id)]; }
  const RoadmapNode& node(int64_t id) const { return nodes_[static_cast<size_t>(id)]; }
  // Every slot, dead ones included (check alive).
  const std::vector<RoadmapNode>& slots() const { return nodes_; }
  std::vector<RoadmapNode>& slots() { return nodes_; }

  // Adds a → b and b → a unless present; returns false when it was present or a == b.
  bool add_edge(int64_t a, int64_t b, double length);
  void remove_edge(int64_t a, int64_t b);
  bool has_edge(int64_t a, int64_t b) const;

  size_t num_nodes() const { return alive_; }
  size_t num_edges() const { return edges_; }

  // Alive nodes within `radius` of p, nearest first (ties by id), at most k (k < 0: all).
  std::vector<int64_t> nearest(const Eigen::Vector3d& p, int k, double radius, int64_t exclude = -1) const;
  bool any_within(const Eigen::Vector3d& p, double radius, int64_t exclude = -1) const;

  struct Search {
    std::vector<double> distance;  // per slot, +inf when unreachable
    std::vector<int64_t> parent;   // per slot, -1 for the source and unreachable nodes
    int64_t settled = 0;           // nodes taken off the queue
    bool reached(int64_t id) const { return distance[static_cast<size_t>(id)] < kInf; }
  };
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  // Dijkstra from `source` over edge lengths.
  Search shortest_paths(int64_t source) const;
  // The same, stopping once every target is settled: their distances and reached() are exact,
  // other nodes' are not. A tour's cost matrix needs only its sites, and DEP's searches from each
  // site over the whole roadmap were a tenth of its cycle in a 600 m² world.
  Search shortest_paths(int64_t source, const std::vector<int64_t>& targets) const;
  // Node ids source..target along the search tree (empty if unreachable).
  static std::vector<int64_t> path_to(const Search& s, int64_t target);

  void clear();

 private:
  uint64_t cell_of(const Eigen::Vector3d& p) const;
  static uint64_t pack(int64_t x, int64_t y, int64_t z);

  double cell_;
  std::vector<RoadmapNode> nodes_;
  std::unordered_map<uint64_t, std::vector<int64_t>> cells_;
  size_t alive_ = 0;
  size_t edges_ = 0;
};

}  // namespace semx::planner
