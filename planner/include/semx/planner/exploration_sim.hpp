// A closed loop without processes: the planner explores a SyntheticWorld with an ideal vehicle
// (follows the path's polyline at `speed`, turns at `yaw_rate`) and the world's camera model, on
// simulated time. semx-perf-planner measures cycle times over whole explorations with it, and the
// tests check termination, collision-freedom and coverage.
//
// Each step of dt: the vehicle moves along the latest released path; every observe_period a
// camera frame updates the known map (the planner hears the changes); then planner.tick(t). The
// vehicle reports HOLDING at the end of a path (as the controller does). It stops when the
// planner is DONE or at max_time.
//
// Emulated semantics (semantic_weight > 0): each of the world's objects becomes a semantic region
// (centre of its box, weight semantic_weight, radius semantic_radius) once one of its surface
// voxels (occupied, next to free space) is known, and turns inactive once observed_fraction of
// them are known: what a semantics module reporting observed_fraction would do.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "semx/planner/exploration_planner.hpp"
#include "semx/planner/synthetic_world.hpp"

namespace semx::planner {

struct ExplorationSimOptions {
  double dt = 0.05;                // s
  double speed = 1.0;              // m/s
  double yaw_rate = 1.0;           // rad/s
  double observe_period = 0.2;     // s between camera frames
  int pixel_step = 4;              // camera rays: every n-th pixel (4: 6 cm apart at 5 m)
  double max_time = 600.0;         // s of simulated time
  double coverage_period = 5.0;    // s between coverage samples (0: only at the end)
  runtime::PinholeCamera camera;   // DESIGN.md §5 defaults
  double semantic_weight = 0.0;    // 0: no regions
  double semantic_radius = 2.0;    // m
  double observed_fraction = 0.5;  // share of an object's surface known when it stops attracting
};

struct ExplorationSimResult {
  bool done = false;
  std::string reason;
  double time_s = 0;    // simulated time at the end
  double distance = 0;  // m flown
  double coverage = 0;  // share of the world's free voxels known
  double time_85 = -1;  // first coverage sample at or above 85 % (s), -1 if never
  std::vector<std::pair<double, double>> coverage_curve;  // (t, coverage) samples
  int64_t cycles = 0;                                     // planning cycles that ran
  int64_t paths = 0;                                      // paths released
  int64_t collisions = 0;         // steps at which the vehicle body overlapped the truth
  double charged_s = 0;           // total planning time charged
  int64_t objects_completed = 0;  // objects observed to observed_fraction (emulated semantics)
  double objects_time = -1;       // when the last of them was (s), -1 if not all were
  std::vector<double> cycle_ms;   // wall time of each cycle that planned
  std::vector<CycleCounters> counters;
  std::vector<PlannedPath> released;  // every path, in order
};

class ExplorationSim {
 public:
  ExplorationSim(const SyntheticWorld& world, ExplorationPlanner& planner,
                 ExplorationSimOptions options = {});

  // Runs until DONE or max_time. `on_step` (optional) sees every step's time and outputs.
  ExplorationSimResult run(
      const std::function<void(double t, const ExplorationPlanner::Output&)>& on_step = nullptr);

  const mapper::StateGrid& known() const { return known_; }
  mapper::StateGrid& known() { return known_; }
  const VehiclePose& pose() const { return pose_; }

 private:
  void observe();
  void move(double dt);
  void update_regions(double t, ExplorationSimResult& r);

  struct Object {
    Eigen::Vector3d centre;
    std::vector<mapper::VoxelKey> surface;
    bool completed = false;
  };
  std::vector<Object> objects_;

  const SyntheticWorld& world_;
  ExplorationPlanner& planner_;
  ExplorationSimOptions options_;
  mapper::StateGrid known_;
  VehiclePose pose_;
  PlannedPath path_;
  size_t next_waypoint_ = 0;
  bool holding_ = true;
  double distance_ = 0;
};

}  // namespace semx::planner
