// Plain values the planner exchanges with its node: the vehicle pose, a path, the roadmap view
// (ROADMAP), the status (PLANNER_STATUS) and what one cycle cost.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "semx/core/states.hpp"

namespace semx::planner {

struct VehiclePose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;  // rad, about world z
  int64_t utime = 0;
};

struct PlannedPath {
  int64_t plan_id = 0;
  std::vector<Eigen::Vector3d> waypoints;  // from the vehicle's position to the goal
  std::vector<double> yaws;                // heading at each waypoint, rad
};

// The status values of the message contract (semx/core/states.hpp).
using core::ControllerState;
using core::PlannerState;

// Work done by one planning cycle: what the planning-time charge is computed from, and the wall
// time of each part (reported, never used for decisions).
struct CycleCounters {
  int64_t samples_drawn = 0;
  int64_t nodes_added = 0;
  int64_t edges_checked = 0;
  int64_t edges_added = 0;
  int64_t box_checks = 0;
  int64_t gain_evaluations = 0;
  int64_t rays = 0;
  int64_t ray_steps = 0;
  int64_t search_settled = 0;
  int64_t paths_searched = 0;  // FUEL's path searches to a view (A*, the detour counted apart)
  int64_t nodes_pruned = 0;
  int64_t edges_pruned = 0;
  double sample_ms = 0, connect_ms = 0, gain_ms = 0, search_ms = 0, total_ms = 0;  // wall time
  double cpu_ms = 0;  // the cycle's CPU time on its thread
};

// Roadmap node flags (roadmap_node_t).
enum RoadmapFlag : int8_t { kFlagRoot = 1, kFlagGoal = 2, kFlagOnPath = 4, kFlagFrontier = 8 };

struct RoadmapView {
  struct Node {
    int64_t id = 0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double yaw = 0, gain = 0, reward = 0, cost = -1, score = 0;  // cost -1: unreachable
    int8_t flags = 0;
  };
  int64_t iteration = 0;
  std::vector<Node> nodes;
  std::vector<std::pair<int64_t, int64_t>> edges;
};

struct StatusReport {
  std::string planner;
  PlannerState state = PlannerState::kInit;
  std::string reason;
  int64_t iteration = 0;
  int32_t num_nodes = 0;
  int32_t num_edges = 0;
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  double best_gain = 0, best_reward = 0, best_score = 0;
  CycleCounters counters;
  double charged_s = 0;
};

}  // namespace semx::planner
