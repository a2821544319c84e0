// A voxel ground truth built from boxes and a depth-camera model that maps it into a StateGrid:
// what the planner's tests and semx-perf-planner explore, without the simulator or the mapper.
//
// Truth: a voxel is occupied when its cube overlaps a solid box with positive volume or is not
// inside the interior box (walls, floor, ceiling); free otherwise. The camera casts one ray per
// `pixel_step`-th pixel of the PinholeCamera (the runtime's convention, level with the body, at
// the body's position) up to z = max_range: voxels before the first occupied one become free,
// that one occupied; pixels whose surface is nearer than min_range are ignored (as the mapper
// ignores them). Each voxel changes at most once per frame, so the changes are a valid delta.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "semx/mapper/map_delta.hpp"
#include "semx/mapper/state_grid.hpp"
#include "semx/runtime/pinhole_camera.hpp"

namespace semx::planner {

struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

class SyntheticWorld {
 public:
  SyntheticWorld(double resolution, const Box& interior, std::vector<Box> solids,
                 const Eigen::Vector3d& start, std::string name = "synthetic");
  // Truth from a function of voxel keys (e.g. the simulator's ground truth of a shipped world);
  // voxels outside `interior` are occupied whatever it says.
  SyntheticWorld(double resolution, const Box& interior,
                 const std::function<bool(const mapper::VoxelKey&)>& occupied, const Eigen::Vector3d& start,
                 std::string name);

  // A 16 x 12 x 2.7 m apartment (≈ 190 m², env3's size): a corridor, six rooms joined by
  // 1.1 m doorways (lintels at 2.1 m), furniture. Start in the corridor.
  static SyntheticWorld apartment(double resolution = 0.1);
  // Two 4 x 4 x 2.5 m rooms side by side joined by a 1.2 m doorway: small, for tests.
  static SyntheticWorld two_rooms(double resolution = 0.1);
  // One empty box room.
  static SyntheticWorld room(const Eigen::Vector3d& size, const Eigen::Vector3d& start,
                             double resolution = 0.1);

  const std::string& name() const { return name_; }
  double resolution() const { return km_.resolution(); }
  const Box& interior() const { return interior_; }
  const std::vector<Box>& solids() const { return solids_; }
  const Eigen::Vector3d& start() const { return start_; }
  // Objects (furniture) for an emulated semantics module (ExplorationSim): boxes.
  const std::vector<Box>& objects() const { return objects_; }
  void set_objects(std::vector<Box> objects) { objects_ = std::move(objects); }

  bool occupied(const mapper::VoxelKey& k) const;
  bool occupied(const Eigen::Vector3d& p) const { return occupied(km_.key(p)); }
  // The vehicle's body box at p overlaps an occupied voxel.
  bool collides(const Eigen::Vector3d& p, const Eigen::Vector3d& size) const;

  // One camera frame from a body at `position` with heading `yaw`; returns the changes applied.
  std::vector<mapper::VoxelChange> observe(mapper::StateGrid& known, const Eigen::Vector3d& position,
                                           double yaw, const runtime::PinholeCamera& camera,
                                           int pixel_step) const;
  // Sets every voxel of the box to its true state (a known region around the start).
  std::vector<mapper::VoxelChange> reveal(mapper::StateGrid& known, const Box& box) const;
  // A grid holding the whole truth (every voxel of the interior's bounds plus one layer).
  mapper::StateGrid full_map() const;

  // Free voxels of the interior, and the share of them `known` knows.
  int64_t free_voxels() const { return free_count_; }
  double coverage(const mapper::StateGrid& known) const;

 private:
  void build(const std::function<bool(const mapper::VoxelKey&)>& solid);
  size_t index(const mapper::VoxelKey& k) const;
  bool in_grid(const mapper::VoxelKey& k) const;

  mapper::KeyMath km_;
  Box interior_;
  std::vector<Box> solids_;
  std::vector<Box> objects_;
  Eigen::Vector3d start_;
  std::string name_;
  mapper::VoxelKey lo_, hi_;  // inclusive key bounds of the dense truth
  std::vector<uint8_t> occupied_;
  int64_t free_count_ = 0;
};

}  // namespace semx::planner
