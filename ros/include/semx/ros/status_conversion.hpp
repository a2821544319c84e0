// PLANNER_STATUS as a diagnostic_msgs/DiagnosticArray with one status named "semx/planner":
// level OK (ERROR when FAILED, WARN when RECOVERING), message "STATE: reason", hardware_id the
// planner's name, and every field as a key/value (numbers printed to round-trip exactly), so
// `rostopic echo` and rqt_runtime_monitor show it.
#pragma once

#include "semx/ros/bridge_values.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

msg::DiagnosticArray to_ros(const PlannerStatus& s, const TimeBase& time);
bool status_from_ros(const msg::DiagnosticArray& m, const TimeBase& time, PlannerStatus& out);

}  // namespace semx::rosbridge
