#include <gtest/gtest.h>

#include <string>

#include "semx/core/states.hpp"

namespace semx::core {
namespace {

TEST(States, PlannerStatesHaveTheirNamesAndOthersNone) {
  EXPECT_STREQ(to_string(PlannerState::kInit), "INIT");
  EXPECT_STREQ(to_string(PlannerState::kExecuting), "EXECUTING");
  EXPECT_STREQ(to_string(PlannerState::kDone), "DONE");
  EXPECT_STREQ(to_string(PlannerState::kUnknown), "none");
  EXPECT_STREQ(to_string(static_cast<PlannerState>(42)), "none");
  for (int v = 0; v <= 5; ++v) EXPECT_EQ(static_cast<int>(planner_state_from_int(v)), v);
  EXPECT_EQ(planner_state_from_int(6), PlannerState::kUnknown);
  EXPECT_EQ(planner_state_from_int(-3), PlannerState::kUnknown);
}

TEST(States, ControllerStatesHaveTheirNames) {
  EXPECT_STREQ(to_string(ControllerState::kIdle), "IDLE");
  EXPECT_STREQ(to_string(ControllerState::kStaleInput), "STALE_INPUT");
  EXPECT_STREQ(to_string(ControllerState::kRejected), "REJECTED");
  EXPECT_STREQ(to_string(static_cast<ControllerState>(9)), "?");
}

}  // namespace
}  // namespace semx::core
