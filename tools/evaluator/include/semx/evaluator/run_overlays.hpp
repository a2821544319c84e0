// What the run folder shows besides the map and the trajectory: the planner's last roadmap and
// the semantic regions, as plain values (the node converts ROADMAP / SEMANTIC_REGIONS), and the
// map itself as an OctoMap file for octovis.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "semx/evaluator/map_picture.hpp"
#include "semx/map/state_grid.hpp"

namespace semx::evaluator {

struct RoadmapOverlay {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<bool> frontier;  // per node: it still sees unknown space (gain)
  std::vector<double> gain;    // per node: its G(n) (empty: not known)
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> edges;
};

// The nodes map.png marks as informative: frontier nodes whose gain is at least a quarter of
// the roadmap's highest (every frontier node when no gains are given). Nearly every DEP node
// sees some unknown voxel, so the flag alone marks the whole roadmap.
std::vector<size_t> informative_nodes(const RoadmapOverlay& roadmap);

struct RegionOverlay {
  Eigen::Vector2d centre;
  double radius = 0;  // m
  std::string label;
  bool active = true;  // still attracting the planner
};

// Edges first (thin, faded), then nodes (1 px grey dots; informative ones 2 px orange),
// then regions (faded circles) with their labels placed on top.
void add_roadmap(MapPicture& picture, const RoadmapOverlay& roadmap);
void add_regions(MapPicture& picture, const std::vector<RegionOverlay>& regions);

// Every known voxel of `grid` as an OctoMap node at the clamping log-odds of its state (the
// mirror holds states, not log-odds). Returns the number of voxels written; throws
// std::runtime_error naming the file when it cannot be written.
int64_t write_octomap_bt(const map::StateGrid& grid, const std::string& path);

}  // namespace semx::evaluator
