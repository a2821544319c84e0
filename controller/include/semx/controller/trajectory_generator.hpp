// From a path and the vehicle's state to a trajectory that is safe to fly, or a reason why there
// is none.
//
//   1. time allocation along the polyline (time_allocation.hpp), control points sampled from it
//      at the knot interval, the first three fixing the vehicle's position and velocity;
//   2. ESDF optimisation (trajectory_optimizer.hpp), kept only within max_deviation of the path;
//   3. uniform time scaling so speed and acceleration are within the limits everywhere;
//   4. the yaw profile (yaw_profile.hpp);
//   5. the dense clearance check (clearance.hpp).
// If 2 is disabled or failed, or 5 fails, the fallback (fallback.hpp: the polyline itself at
// fallback_speed_factor × the speed limit) goes through 3-5 instead. If that fails too, there
// is no trajectory: nothing that the ESDF says collides is ever returned.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "semx/controller/clearance.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/distance_field.hpp"
#include "semx/controller/path.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/controller/trajectory_optimizer.hpp"
#include "semx/controller/vehicle_state.hpp"

namespace semx::controller {

struct StartState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

// Why an optimised trajectory was not flown (the fallback was tried instead).
enum class FallbackCause { kNone, kOptimizerOff, kOptimizerFailed, kStrays, kTooClose };

struct GenerationResult {
  bool ok = false;  // `trajectory` is safe to fly
  FallbackCause cause = FallbackCause::kNone;
  Trajectory trajectory;  // plan_id, start_utime left to the caller
  std::string reason;     // why the fallback was used, or why there is no trajectory
  OptimizerReport optimizer;
  ClearanceReport clearance;  // of the returned trajectory, or of the last one tried
  double time_scale = 1.0;    // knot interval stretch applied for the limits
  bool slowed = false;        // optimised at the fallback's cruise speed (the full-speed curve failed)
  int slow_zones = 0;         // ... only near this many points (0: along the whole path)
  int squared_headings = 0;   // path points whose heading was turned to face an obstacle
  int repaired_headings = 0;  // instants of the flown curve whose heading was held square (heading_repairs)
};

// Places along a path to fly at a lower speed: spheres around where a full-speed curve failed.
struct SlowZones {
  struct Zone {
    Eigen::Vector3d centre;
    double radius;
  };
  // The polyline cut where it enters and leaves the zones, the headings spread over each cut
  // segment by length, and each piece's cruise speed: v_slow when its middle is in a zone.
  struct Split {
    std::vector<Eigen::Vector3d> points;
    std::vector<double> yaws;
    std::vector<double> speed;  // per piece
  };
  static constexpr double kMinPiece = 0.01;  // m: no piece shorter

  // A zone around p; a p within half a zone's radius of its centre grows that zone 1.5 times
  // instead (false).
  bool add(const Eigen::Vector3d& p, double radius);
  Split split(const std::vector<Eigen::Vector3d>& polyline, const std::vector<double>& yaws, double v_slow,
              double v_fast) const;

  std::vector<Zone> zones;
};

class TrajectoryGenerator {
 public:
  explicit TrajectoryGenerator(const ControllerConfig& config)
      : config_(config), optimizer_(config.optimizer) {}

  // `polyline[0]` is the start position; `yaws` are the unwrapped headings at each polyline
  // point (yaws[0] = start.yaw). `max_speed` > 0 lowers the configured speed limit.
  GenerationResult generate(const std::vector<Eigen::Vector3d>& polyline, const std::vector<double>& yaws,
                            const StartState& start, double max_speed, const DistanceField& field) const;
  // A path from the planner as the controller flies it (Controller, semx-controller-replay): from
  // the vehicle's state along flight_polyline() (path.hpp), at most the path's max_speed. The
  // path's start must already have been checked (check_path_start).
  GenerationResult generate(const Path& path, const VehicleState& vehicle, const DistanceField& field) const;

  // The rule a new trajectory must meet (bound = half_size + margin); an optimised one also the
  // turned body's reach (clearance.turned_body). The fallback follows the planner's path exactly,
  // whose clearance is the planner's to keep: in a doorway its centre line is 0.35 m from the
  // jambs in the ESDF (0.45 m in the world), below the reach of a body heading diagonally.
  ClearanceRule generation_rule(bool optimised = true) const;
  // The rule a flown trajectory is held to on each new ESDF (bound = half_size + brake_margin):
  // an optimised one also the turned body's reach, with no margin. Its far part may have been
  // outside the mapper's window (free) when it was generated, so the turned body is checked
  // there for the first time now.
  ClearanceRule flight_rule(bool optimised = false) const;

  // The farthest the curve gets from the polyline (sampled every kDeviationStep of its time), and
  // where on the curve (`where`, when given).
  static double deviation(const PositionSpline& curve, const std::vector<Eigen::Vector3d>& polyline,
                          Eigen::Vector3d* where = nullptr);
  static constexpr double kDeviationStep = 0.05;  // s
  // The point of the polyline nearest to p.
  static Eigen::Vector3d nearest_on_path(const Eigen::Vector3d& p,
                                         const std::vector<Eigen::Vector3d>& polyline);

  // Speed limit for a path asking for `max_speed` (0 = none).
  double speed_limit(double max_speed) const;

  // Step 1 alone: the optimiser's starting point (also what the perf tool times it from), and
  // the times the polyline's points are passed on it. It cruises at v_max and starts at the
  // vehicle's velocity, no faster than max(v_max, v_start); `segment_speed` (one per segment, or
  // empty) slows some segments further (TimedPolyline).
  PositionSpline initial_spline(const std::vector<Eigen::Vector3d>& polyline, const StartState& start,
                                double v_max, std::vector<double>* point_times = nullptr,
                                double v_start = 0.0, const std::vector<double>& segment_speed = {}) const;

 private:
  // The vehicle's velocity (zero when not finite), no faster than v_max: where both curves start.
  static Eigen::Vector3d start_velocity(const StartState& start, double v_max);
  bool finish(Trajectory& trajectory, const std::vector<double>& times, const std::vector<double>& yaws,
              double v_max, const DistanceField& field, GenerationResult& result) const;

  ControllerConfig config_;
  TrajectoryOptimizer optimizer_;
};

}  // namespace semx::controller
