// The one place that knows both semx/core/states.hpp and the .lcm constants: the enums every
// process uses must be the message contract's values, checked when semx_runtime is built.
#include <semx/controller_status_t.hpp>
#include <semx/planner_status_t.hpp>

#include "semx/core/states.hpp"

namespace semx::runtime {
namespace {

template <class E>
constexpr bool same(E e, int v) {
  return static_cast<int>(e) == v;
}
using core::ControllerState;
using core::PlannerState;

static_assert(same(PlannerState::kInit, planner_status_t::INIT) &&
                  same(PlannerState::kPlanning, planner_status_t::PLANNING) &&
                  same(PlannerState::kExecuting, planner_status_t::EXECUTING) &&
                  same(PlannerState::kRecovering, planner_status_t::RECOVERING) &&
                  same(PlannerState::kDone, planner_status_t::DONE) &&
                  same(PlannerState::kFailed, planner_status_t::FAILED),
              "core::PlannerState must be planner_status_t's state constants");
static_assert(same(ControllerState::kIdle, controller_status_t::IDLE) &&
                  same(ControllerState::kTracking, controller_status_t::TRACKING) &&
                  same(ControllerState::kBraking, controller_status_t::BRAKING) &&
                  same(ControllerState::kHolding, controller_status_t::HOLDING) &&
                  same(ControllerState::kStaleInput, controller_status_t::STALE_INPUT) &&
                  same(ControllerState::kRejected, controller_status_t::REJECTED),
              "core::ControllerState must be controller_status_t's state constants");

}  // namespace
}  // namespace semx::runtime
