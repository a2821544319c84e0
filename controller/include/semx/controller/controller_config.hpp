// Every parameter of the controller, with its default. This struct is the one place defaults are
// set; docs/controller.md and controller/config/controller.yaml mirror it (a test loads the YAML
// file and compares it with these defaults).
//
// YAML layout: top-level rates, then one mapping per struct below (limits, clearance,
// trajectory, optimizer, path, tracking, safety), keys named as the fields.
#pragma once

#include <cmath>

#include "semx/runtime/config.hpp"

namespace semx::controller {

// Dynamic limits every output trajectory respects at every instant (Euclidean norms).
struct LimitsConfig {
  double max_velocity = 1.0;      // m/s; a path's max_speed may lower it, never raise it
  double max_acceleration = 2.0;  // m/s²
  double max_yaw_rate = 1.0;      // rad/s
};

struct ClearanceConfig {
  // m, ESDF distance below this is a collision: the body box's half width (0.5 x 0.5 m). Turned
  // by 45° it reaches 0.354 m, which margin covers where the planner's paths go (0.42 m from
  // occupied and unknown voxels everywhere but doorways). The floor of an escape (allow_escape).
  double half_size = 0.25;
  // m, a new trajectory keeps ESDF distance >= half_size + margin = 0.32. A 0.9-1.0 m door whose
  // jambs the map grows by a voxel is 7-8 free voxels wide, where the ESDF (centre distances minus
  // half a voxel, trilinear) peaks at 0.35 m; 0.32 plus the check's 0.017 m pad fits under it
  // (with 0.4 no such doorway could be passed, and env3 stayed below 85 %). The planner keeps
  // 0.42 m everywhere but in such doorways (docs/planner.md), and the optimiser aims at
  // bound + target_margin, so those, not this bound, set the usual distance.
  double margin = 0.07;
  double brake_margin = 0.05;  // m, a flown trajectory brakes when it would come below half_size
                               // + brake_margin (smaller than margin: no brake on map jitter)
  // The body box turned by the trajectory's yaw (turned_body): an optimised trajectory also keeps
  // the box's reach toward the nearest obstacle (along the ESDF gradient) + footprint_margin. The
  // bounds above assume a face toward the obstacle: beside a wall's end the box's corner reaches
  // √2 × 0.25 = 0.354 m. An optimised trajectory that cut a path's corner passed a wall's end at
  // 0.34 m (ESDF 0.328 > 0.32) heading -89°, diagonally from it, and the box's corner hit it
  // (env3, 30 samples, seed 3, at 260 s). Not for the fallback, which is the planner's path (in a
  // doorway its centre line is 0.35 m from the jambs in the ESDF, 0.45 m in the world: with the
  // rule, a vehicle heading diagonally there had every path rejected for 800 s, env3 seed 2), nor
  // for braking. Where the gradient vanishes (a ridge) the direction is unknown: the bounds apply.
  double half_height = 0.15;       // m, the body box's (0.3 m high)
  double footprint_margin = 0.02;  // m
  bool turned_body = true;
  // Turn the heading at each path point closer to an obstacle than a corner's reach (√2 half_size
  // + footprint_margin) by at most 45°, so that a face of the body looks at the obstacle there
  // (body_heading.hpp). For every trajectory, the fallback too: it is the one that follows the
  // path through its doorway and passage points exactly.
  bool square_headings = true;
  // An optimised curve cuts corners, so it can pass an obstacle closer than a corner's reach where
  // no path point does. Where it breaks the turned-body rule, the heading target is held square to
  // that obstacle for heading_hold s on either side of the instant and the curve checked again, at
  // most heading_repairs times (body_heading.hpp), before the slower curves are tried. 0: off.
  int heading_repairs = 8;
  double heading_hold = 0.3;    // s
  // When holding each failing instant's square in turn does not pass, try again with failures
  // within two holds' length joined: one heading, or a turn of at most half max_yaw_rate, that
  // meets them all (a doorway's two jambs want different squares; each hold undid the other's).
  bool join_holds = true;
  // The fallback's heading held square the same way where its turned body would touch, when that
  // is enough; otherwise it is flown as it is (its bound is the planner's, see turned_body).
  bool square_fallback = true;
  double check_spacing = 0.02;  // m, arc length between dense clearance samples
  // A trajectory that starts below the bound (the vehicle already is) may climb out of it
  // without getting closer than its start; otherwise such a vehicle could never move again.
  bool allow_escape = true;
  // Space outside the ESDF window: free (max_distance) or an obstacle.
  bool outside_is_obstacle = false;

  double bound() const { return half_size + margin; }
  double brake_bound() const { return half_size + brake_margin; }
  // ESDF distance below which square_headings turns a path point's heading.
  double square_within() const { return std::sqrt(2.0) * half_size + footprint_margin; }
};

struct TrajectoryConfig {
  double knot_interval = 0.25;         // s, of the uniform cubic B-spline (before time scaling)
  double fallback_speed_factor = 0.5;  // fallback cruise speed as a fraction of max_velocity
  // m: an optimised trajectory that strays farther than this from the path goes to the fallback.
  // The planner keeps the path 0.42 m from occupied and unknown voxels; the ESDF the trajectory is
  // checked against sees occupied ones only (the camera never sees the vehicle's surroundings), so
  // only near the path is the unknown space known to be clear: within 0.4 m the trajectory's centre
  // never reaches an unknown voxel. 0.25 m sent the optimiser's ordinary corner cuts at 1 m/s to
  // the half-speed fallback. A trajectory that left a path's
  // sharp climb by 0.6 m, still moving down from the last path, hit the unmapped top of a sofa
  // (env2, 30 samples, seed 1).
  double max_deviation = 0.4;
  // m: where the full-speed optimised curve fails (too close, or strays), it is optimised again at
  // the fallback's cruise speed within this distance of the place only, up to slow_zone_tries
  // places, before the whole path is (0: off, the whole path at once).
  double slow_zone_radius = 1.5;
  int slow_zone_tries = 3;
};

struct OptimizerConfig {
  int max_iterations = 200;         // L-BFGS iterations; 0 disables it (always the fallback)
  double weight_smoothness = 1.0;   // on squared jerk differences of the control points (m²)
  double weight_clearance = 40.0;   // on squared distance below the clearance target (m²)
  double weight_feasibility = 1.0;  // on squared relative excess of velocity/acceleration
  double target_margin = 0.1;       // m, optimiser's target distance = clearance bound + this
  // On squared offsets of control points beyond fidelity_tolerance from the initial curve, which
  // follows the path: without it, smoothness rounds DEP's many-waypoint paths past
  // trajectory.max_deviation and they are flown at half speed or on the fallback (docs/controller.md,
  // "Fidelity": over ten seeds it halved the fallbacks and brought 85 % coverage earlier). 0: off.
  double weight_fidelity = 20.0;
  double fidelity_tolerance = 0.25;  // m
  int samples_per_segment = 2;       // curve points per knot interval in the clearance cost
};

struct PathConfig {
  int max_waypoints = 200;           // longer paths are rejected
  double max_segment_length = 10.0;  // m, consecutive waypoints farther apart are rejected
  double max_start_offset = 1.0;     // m, first waypoint farther from the vehicle is rejected
  double max_age = 2.0;              // s, a path waiting longer for fresh inputs is rejected
};

struct TrackingConfig {
  double position_gain = 2.0;      // 1/s, velocity command per metre of position error
  double velocity_gain = 0.5;      // velocity command per m/s of velocity error
  double accel_feedforward = 0.3;  // s, × reference acceleration: the vehicle's velocity lag
  double yaw_feedforward = 0.5;    // s, × reference yaw rate: the vehicle's yaw-angle lag
  double max_command_speed = 1.5;  // m/s, norm of any velocity command
  // m/s, |vertical| of any velocity command: the simulator's vehicle climbs at most 1 m/s and
  // rejects (then hovers on) a command beyond 1.25 m/s. Without it, holding the end of a climb
  // 1.2 m above the vehicle asked for 1.5 m/s up, every command was rejected, and the vehicle
  // hovered there for the rest of the run (env3 seed 1, from 61 s).
  double max_command_speed_z = 1.0;
};

struct SafetyConfig {
  double check_horizon = 2.0;     // s of the flown trajectory checked against each new ESDF
  double max_odometry_age = 0.2;  // s of message time; older odometry stops the vehicle
  double max_esdf_age = 1.0;      // s of message time; an older ESDF stops the vehicle
  // m: a vehicle this far from its reference brakes (BRAKING, so the planner plans again from
  // where it is) instead of chasing it across the path's corners. Held 2.6 s by a wall it touched
  // (every step turned its corner into it), the vehicle then flew at the command limit (1.5 m/s)
  // straight for a reference 2 m ahead, below the path's climb, into a chair (env3, fuel's latency
  // tour, seed 1, at 175 s). Tracking errors are a few cm in flight. 0: off.
  double max_tracking_error = 0.5;
};

struct ControllerConfig {
  double rate_hz = 100.0;        // control steps per simulated second
  double status_rate_hz = 10.0;  // CONTROLLER_STATUS period (besides every change)
  LimitsConfig limits;
  ClearanceConfig clearance;
  TrajectoryConfig trajectory;
  OptimizerConfig optimizer;
  PathConfig path;
  TrackingConfig tracking;
  SafetyConfig safety;
};

void load(runtime::ConfigMap& m, ControllerConfig& c);

}  // namespace semx::controller
