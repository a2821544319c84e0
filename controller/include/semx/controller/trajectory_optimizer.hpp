// ESDF optimisation of a position B-spline with L-BFGS (LBFGS++).
//
// Variables: every control point except the first three and the last three, which fix the
// start state (position, velocity, acceleration) and the stop at the goal. Cost:
//   smoothness   w_s · Σ |Q_{i+3} - 3Q_{i+2} + 3Q_{i+1} - Q_i|²           (jerk control points)
//   clearance    w_c · Σ max(0, d_target - d(p))²  over curve points p (samples_per_segment per
//                knot interval), gradient from the field's trilinear gradient
//   feasibility  w_f · Σ max(0, |V_i|²/v_max² - 1)² + max(0, |A_i|²/a_max² - 1)²
// The optimiser works on offsets from the initial control points, so results do not depend on
// where in the world the path lies.
#pragma once

#include <string>

#include "semx/controller/bspline.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/distance_field.hpp"

namespace semx::controller {

struct OptimizerReport {
  bool ran = false;     // there was something to optimise
  bool failed = false;  // the solver threw or produced non-finite values
  int iterations = 0;
  int evaluations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string message;  // the solver's complaint when it failed
};

class TrajectoryOptimizer {
 public:
  explicit TrajectoryOptimizer(const OptimizerConfig& config) : config_(config) {}

  // Improves `spline` in place (the lowest-cost point the solver visited); on failure it keeps
  // the best point found so far, which may be the initial one.
  OptimizerReport optimize(PositionSpline& spline, const DistanceField& field, double max_velocity,
                           double max_acceleration, double clearance_target) const;

 private:
  OptimizerConfig config_;
};

}  // namespace semx::controller
