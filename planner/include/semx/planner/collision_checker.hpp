// Collision checks of roadmap nodes and edges against the map, with the clearance the
// controller needs (docs/controller.md, "For the planner": waypoints ≥ 0.4 m, in ESDF distance,
// from occupied and unknown space).
//
//   node_free(p):    no occupied and no unknown voxel overlaps the vehicle box grown by `margin`
//                    (0.35 × 0.35 × 0.25 m half sizes by default) nor comes within `clearance`
//                    (0.45 m, Euclidean, to the voxel's cube) of p: the box is the body, the ball
//                    the controller's distance bound plus 5 cm;
//   passage_free(p): the same with `passage_clearance` (0.40 m): where the vehicle may pass
//                    without stopping (edge samples, passage nodes in doorways);
//   edge_free(a, b): passage_free at points of the segment at most edge_step apart (a and b are
//                    nodes, checked already). Every point of the segment is within edge_step/2
//                    of a checked point, so it keeps passage_clearance - edge_step/2 (0.35 m to
//                    the cube, >= 0.40 m to the voxel centres the ESDF measures);
//   root_edge_free(root, b): edge_free when the root itself is node_free; otherwise points within
//                    root_escape_radius of the root are checked with the bare vehicle box against
//                    occupied voxels only: the vehicle may leave a pose whose surroundings are not
//                    mapped yet (the camera never sees the cone above and below itself: 0.6 m deep
//                    for a ±37° vertical field of view and a 0.45 m clearance) or that drifted
//                    close to a wall.
//
// The centre line is first walked voxel by voxel (no occupied or unknown voxel on it), which
// rejects edges through walls and into unknown space for the price of one ray.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semx/mapper/state_grid.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

class CollisionChecker {
 public:
  explicit CollisionChecker(const CollisionConfig& config);

  void set_grid(const mapper::StateGrid* grid) { grid_ = grid; }
  const mapper::StateGrid* grid() const { return grid_; }
  // Half sizes of the box that bounds everything node_free() looks at.
  const Eigen::Vector3d& half_extent() const { return reach_; }

  bool node_free(const Eigen::Vector3d& p) const;
  bool passage_free(const Eigen::Vector3d& p) const;
  bool edge_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  bool root_edge_free(const Eigen::Vector3d& root, const Eigen::Vector3d& b) const;
  // The bare vehicle box at p overlaps no occupied voxel (unknown allowed).
  bool vehicle_free(const Eigen::Vector3d& p) const;
  // Moves p away from the occupied and unknown voxels within `clearance` of it (each pushes by
  // how much it intrudes, along the line from its cube's nearest point), up to `iterations` times
  // and by at most max_step each; true when p ends node_free (passage_free with `passage`).
  // Centres a draw that fell too close to a wall, and in a doorway between both jambs, so narrow
  // passages get nodes and edges.
  bool centre(Eigen::Vector3d& p, int iterations = 3, double max_step = 0.3, bool passage = false) const;

  // Box checks made so far (for the planning-time charge); reset by the caller.
  int64_t box_checks() const { return box_checks_; }
  void reset_counters() const { box_checks_ = 0; }

 private:
  // No voxel (occupied, or unknown when unknown_is_occupied) overlaps the open box p ± half nor,
  // when radius > 0, has its cube within `radius` of p.
  bool region_free(const Eigen::Vector3d& p, const Eigen::Vector3d& half, double radius,
                   bool unknown_is_occupied) const;
  bool centre_line_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double skip_radius) const;
  bool samples_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double escape_radius) const;

  CollisionConfig config_;
  Eigen::Vector3d body_half_;     // vehicle box + margin
  Eigen::Vector3d vehicle_half_;  // bare vehicle box
  Eigen::Vector3d reach_;         // max(body_half_, clearance) per axis
  const mapper::StateGrid* grid_ = nullptr;
  mutable int64_t box_checks_ = 0;
};

}  // namespace semx::planner
