// What the controller reports (CONTROLLER_STATUS as plain data) and counts.
#pragma once

#include <cstdint>
#include <string>

#include "semx/core/states.hpp"

namespace semx::controller {

using core::ControllerState;  // the message contract's values and names (semx/core/states.hpp)

struct ControllerStatus {
  int64_t plan_id = -1;  // the path the state refers to; -1 before the first
  ControllerState state = ControllerState::kIdle;
  std::string reason;
  double tracking_error = 0.0;  // m, |p_ref - p| at this step
  double tracking_rms = 0.0;    // m, over the current trajectory so far
  double progress = 0.0;        // 0..1 of the current trajectory's duration
};

struct ControllerCounters {
  int64_t paths = 0;               // PLAN_PATHs received
  int64_t superseded = 0;          // replaced by a newer path before they were processed
  int64_t rejected = 0;            // bad paths (empty, non-finite, jumps, too many, too old, too far)
  int64_t unsafe = 0;              // paths for which neither trajectory passed the clearance check
  int64_t trajectories = 0;        // trajectories started
  int64_t optimized = 0;           // ... of which optimised
  int64_t slowed = 0;              //   at the fallback's cruise speed (the full-speed one failed)
  int64_t slowed_near = 0;         //     ... only near where it failed (trajectory.slow_zone_radius)
  int64_t fallbacks = 0;           // ... of which the fallback, because the optimised one
  int64_t fallback_strays = 0;     //   strayed from the path (trajectory.max_deviation)
  int64_t fallback_too_close = 0;  //   failed the clearance check
  int64_t squared_headings = 0;    // path points whose heading was turned to face an obstacle
  int64_t repaired_headings = 0;   // instants of flown optimised curves whose heading was held square
  int64_t brakes = 0;              // predicted collisions
  int64_t off_track = 0;           // stops farther than safety.max_tracking_error from the reference
  int64_t stale_stops = 0;         // entries into STALE_INPUT
};

}  // namespace semx::controller
