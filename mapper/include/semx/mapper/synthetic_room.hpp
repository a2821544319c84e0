// An analytic box room with box obstacles that renders exact depth images: the mapper's tests and
// benchmark use it so they need neither the simulator nor any data files.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "semx/runtime/pinhole_camera.hpp"

namespace semx::mapper {

struct Aabb {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

class SyntheticRoom {
 public:
  // The room is the inside of `interior` (walls, floor and ceiling are its faces); `boxes` are
  // solid obstacles inside it.
  SyntheticRoom(const Aabb& interior, std::vector<Aabb> boxes);
  // 6 x 5 x 2.7 m (corner at the origin) with a table, a cabinet, a sofa and a pillar. Every
  // point of it is within 5 m of any camera within 0.5 m (horizontally) of (3, 2.5) at a height
  // of 1.2 to 1.5 m, so such a camera's depth images have no 0xFFFF pixels.
  static SyntheticRoom furnished();

  const Aabb& interior() const { return interior_; }
  const std::vector<Aabb>& boxes() const { return boxes_; }

  // Parameter t >= 0 of the first surface hit by origin + t * dir (+inf when none).
  double cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // z-depth image in millimetres under the runtime::PinholeCamera convention: 0 below the
  // camera's min_range, 0xFFFF beyond its max_range.
  std::vector<uint16_t> render(const runtime::PinholeCamera& camera,
                               const Eigen::Isometry3d& T_world_optical) const;
  // Inside a box or outside the interior.
  bool solid(const Eigen::Vector3d& p) const;

 private:
  Aabb interior_;
  std::vector<Aabb> boxes_;
};

// Camera poses along a loop of radius 0.45 m around the furnished room's centre, turning 1.5 times
// per loop while bobbing in height and pitch: pose k of `per_loop` (the benchmark's and the
// tests' trajectory). A few millimetres of offset keep returns off exact voxel boundaries, where
// round-number synthetic geometry and millimetre depths would otherwise put thousands of end
// points exactly on a boundary (real depth never does), and any two implementations round
// those differently.
Eigen::Isometry3d room_loop_pose(int k, int per_loop);

// Pose of a forward-looking camera's optical frame for a body at `position` with yaw about z and
// pitch about the body's y axis (positive pitch looks down).
Eigen::Isometry3d camera_pose(const Eigen::Vector3d& position, double yaw, double pitch = 0.0);

}  // namespace semx::mapper
