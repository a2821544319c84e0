// The content of the ROADMAP and SEMANTIC_REGIONS messages as plain values, for the processes that
// draw or forward them without planning (the viewer, the ROS bridge): one definition, so that a
// field added to the contract is added once.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace semx::core {

// One node of ROADMAP.
struct RoadmapNode {
  int64_t id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  double gain = 0.0;
  double reward = 0.0;
  double cost = 0.0;
  double score = 0.0;
  int flags = 0;  // kRoot | kGoal | kOnPath | kFrontier (roadmap_node_t's constants)
  static constexpr int kRoot = 1, kGoal = 2, kOnPath = 4, kFrontier = 8;
};

// ROADMAP.
struct Roadmap {
  int64_t utime = 0;
  int64_t iteration = 0;
  std::vector<RoadmapNode> nodes;
  std::vector<std::pair<int64_t, int64_t>> edges;  // node ids
};

// One entry of SEMANTIC_REGIONS: the paper's S_i = (p, label, w, r) and what semantics knows of it.
struct Region {
  int64_t id = 0;
  int class_id = 0;
  std::string label;
  int instance = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double weight = 0.0;
  double radius = 0.0;
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  double confidence = 0.0;
  int observations = 0;
  double observed_fraction = 0.0;
  bool active = true;
};

}  // namespace semx::core
