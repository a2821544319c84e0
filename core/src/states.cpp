#include "semx/core/states.hpp"

namespace semx::core {

const char* to_string(PlannerState s) {
  switch (s) {
    case PlannerState::kUnknown:
      return "none";
    case PlannerState::kInit:
      return "INIT";
    case PlannerState::kPlanning:
      return "PLANNING";
    case PlannerState::kExecuting:
      return "EXECUTING";
    case PlannerState::kRecovering:
      return "RECOVERING";
    case PlannerState::kDone:
      return "DONE";
    case PlannerState::kFailed:
      return "FAILED";
  }
  return "none";
}

PlannerState planner_state_from_int(int v) {
  return v >= 0 && v <= 5 ? static_cast<PlannerState>(v) : PlannerState::kUnknown;
}

const char* to_string(ControllerState s) {
  switch (s) {
    case ControllerState::kIdle:
      return "IDLE";
    case ControllerState::kTracking:
      return "TRACKING";
    case ControllerState::kBraking:
      return "BRAKING";
    case ControllerState::kHolding:
      return "HOLDING";
    case ControllerState::kStaleInput:
      return "STALE_INPUT";
    case ControllerState::kRejected:
      return "REJECTED";
  }
  return "?";
}

}  // namespace semx::core
