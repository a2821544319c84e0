// The dense clearance check every trajectory passes before it is flown, and that each new ESDF
// re-runs on the part about to be flown.
//
// Samples are at most `spacing` apart along the curve, so every point of the curve lies within
// spacing/2 of a sample, where the field is at most lipschitz·spacing/2 lower: a sample passes
// only if its distance minus that pad meets the bound. So the bound holds on the whole curve,
// not only at the samples.
#pragma once

#include <Eigen/Core>

#include "semx/controller/distance_field.hpp"
#include "semx/controller/trajectory.hpp"

namespace semx::controller {

struct ClearanceRule {
  double bound = 0.4;          // m, required distance
  double hard_bound = 0.3;     // m, never below this, even when escaping
  double spacing = 0.02;       // m of arc length between samples
  bool allow_escape = true;    // a start below `bound` may climb out without getting closer
  double escape_slack = 0.01;  // m, how much closer than its start an escape may wobble
  bool require_exit = true;    // an escape must reach the bound before t1 (off for a horizon)
  // m per m of arc: a start below hard_bound (the body touches, or nearly: the map's voxels
  // overstate obstacles by up to a voxel) may escape too, when its distance rises by at least this
  // along the curve until it reaches hard_bound, so it moves away at 30° or more and never slides
  // along the obstacle. Without it a vehicle that touched a chair had every trajectory refused and
  // hovered there for the 225 s left of its run (env3, fuel's latency tour, seed 1). 0: no such
  // escape.
  double contact_rise = 0.5;
  // The body box, turned by the trajectory's yaw: outside an escape, a sample also needs the box's
  // reach toward its nearest obstacle (the support along the ESDF gradient) plus footprint_margin.
  // 0 = off. `bound` assumes a face toward the obstacle; a corner reaches up to √2 farther.
  double footprint_half_xy = 0.0;  // m, half width and length
  double footprint_half_z = 0.0;   // m, half height
  double footprint_margin = 0.0;   // m
};

// Below this |∇distance| (a ridge between obstacles, e.g. a doorway's centre line) the nearest
// obstacle's direction is unknown: only `bound` applies, and no heading is squared to it.
constexpr double kRidgeGradient = 0.5;

// How far a box of half sizes (half_xy, half_xy, half_z), turned by `yaw`, reaches along the
// unit direction n (world frame).
double footprint_reach(const Eigen::Vector3d& n, double yaw, double half_xy, double half_z);

struct ClearanceReport {
  bool ok = true;
  bool escaping = false;         // started below the bound
  double min_distance = 1e300;   // smallest sampled distance, m
  double min_time = 0.0;         // when (s since the trajectory's start)
  double violation_time = -1.0;  // first sample breaking the rule, s; < 0 when none
  Eigen::Vector3d violation_point = Eigen::Vector3d::Zero();
  double violation_distance = 0.0;
  bool footprint = false;  // the violation is the turned body's reach, not `bound`
  // A footprint violation's obstacle direction (the unit ESDF gradient, pointing away from it) and
  // the farthest the body may reach toward it there: what a heading must meet (body_heading.hpp).
  Eigen::Vector3d violation_normal = Eigen::Vector3d::Zero();
  double reach_allowed = 0.0;
  int samples = 0;
};

// Checks trajectory times [t0, t1] (clamped to the trajectory) against `field`.
ClearanceReport check_clearance(const Trajectory& trajectory, const DistanceField& field, double t0,
                                double t1, const ClearanceRule& rule);

}  // namespace semx::controller
