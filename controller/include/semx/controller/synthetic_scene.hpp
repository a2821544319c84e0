// Random cluttered scenes with a known collision-free path, for tests and the perf tool: boxes
// around an 8-waypoint random walk, an exact ESDF of them on a grid like ESDF_LOCAL's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/controller/grid_distance_field.hpp"

namespace semx::controller {

struct Box {
  Eigen::Vector3d lo, hi;
  // Signed Euclidean distance (negative inside).
  double distance(const Eigen::Vector3d& p) const;
};

struct SceneOptions {
  double path_length = 10.0;  // m, total
  int waypoints = 8;
  int obstacles = 40;             // boxes tried; those too close to the path are moved
  double resolution = 0.1;        // m
  double max_distance = 2.0;      // m, ESDF clamp
  double min_clearance = 0.45;    // m, of the path from every box (grid values checked too)
  double max_turn = 1.75;         // rad, largest turn between segments
  bool floor_and_ceiling = true;  // slabs below z = 0 and above z = 3
};

struct SyntheticScene {
  std::vector<Box> boxes;
  std::vector<Eigen::Vector3d> path;
  std::vector<double> yaws;  // heading along each segment (the last repeats)
  GridDistanceField field;
  double exact_distance(const Eigen::Vector3d& p) const;
};

SyntheticScene make_cluttered_scene(uint64_t seed, const SceneOptions& options = SceneOptions());

// Samples `exact` at the cell centres of a grid (clamped to ±max_distance).
GridDistanceField rasterize_boxes(const std::vector<Box>& boxes, const Eigen::Vector3d& origin,
                                  double resolution, int nx, int ny, int nz, double max_distance,
                                  OutsideWindow outside);

}  // namespace semx::controller
