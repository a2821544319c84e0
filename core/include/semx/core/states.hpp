// The state enums of the message contract (planner_status_t.state, controller_status_t.state)
// with their names, defined once for every process that sends or reads them. The values are the
// .lcm constants; runtime/src/state_constants.cpp checks them at compile time, where both are
// known, so a changed .lcm file fails the build instead of a run.
#pragma once

#include <cstdint>

namespace semx::core {

enum class PlannerState : int8_t {
  kUnknown = -1,  // not a message value: what a listener holds before the first PLANNER_STATUS
  kInit = 0,
  kPlanning = 1,
  kExecuting = 2,
  kRecovering = 3,
  kDone = 4,
  kFailed = 5,
};
// "INIT", "PLANNING", ..., "none" for kUnknown and anything else.
const char* to_string(PlannerState s);
PlannerState planner_state_from_int(int v);  // kUnknown for a value that is no state

enum class ControllerState : int8_t {
  kIdle = 0,        // nothing to fly (start-up, or inputs fresh again after a stop): hover
  kTracking = 1,    // flying a trajectory
  kBraking = 2,     // a new ESDF predicted a collision: trajectory dropped, hover, replan
  kHolding = 3,     // the trajectory ended: holding its end point
  kStaleInput = 4,  // odometry or ESDF too old (or missing): trajectory dropped, hover
  kRejected = 5     // the last path was bad or had no safe trajectory: hover, replan
};
// "IDLE", "TRACKING", ..., "?" for a value that is no state.
const char* to_string(ControllerState s);

}  // namespace semx::core
