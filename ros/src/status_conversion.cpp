#include "semx/ros/status_conversion.hpp"

#include <cstdio>
#include <cstdlib>
#include <map>

#include "semx/core/states.hpp"

namespace semx::rosbridge {

namespace {

constexpr const char* kName = "semx/planner";

std::string number(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

bool parse_double(const std::string& s, double& v) {
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end && *end == '\0' && !s.empty();
}

bool parse_int(const std::string& s, int64_t& v) {
  char* end = nullptr;
  v = std::strtoll(s.c_str(), &end, 10);
  return end && *end == '\0' && !s.empty();
}

}  // namespace

msg::DiagnosticArray to_ros(const PlannerStatus& s, const TimeBase& time) {
  msg::DiagnosticArray a;
  a.header.stamp_ns = time.to_ros_ns(s.utime);
  msg::DiagnosticStatus d;
  const auto state = static_cast<core::PlannerState>(s.state);
  d.level = state == core::PlannerState::kFailed       ? msg::DiagnosticStatus::ERROR
            : state == core::PlannerState::kRecovering ? msg::DiagnosticStatus::WARN
                                                       : msg::DiagnosticStatus::OK;
  d.name = kName;
  const std::string state_name = core::to_string(state);
  d.message = s.reason.empty() ? state_name : state_name + ": " + s.reason;
  d.hardware_id = s.planner;
  d.values = {{"state", state_name},
              {"reason", s.reason},
              {"iteration", std::to_string(s.iteration)},
              {"num_nodes", std::to_string(s.num_nodes)},
              {"num_edges", std::to_string(s.num_edges)},
              {"goal_x", number(s.goal.x())},
              {"goal_y", number(s.goal.y())},
              {"goal_z", number(s.goal.z())},
              {"best_gain", number(s.best_gain)},
              {"best_reward", number(s.best_reward)},
              {"best_score", number(s.best_score)},
              {"total_ms", number(s.total_ms)},
              {"charged_s", number(s.charged_s)}};
  a.status.push_back(std::move(d));
  return a;
}

bool status_from_ros(const msg::DiagnosticArray& m, const TimeBase& time, PlannerStatus& out) {
  if (m.status.size() != 1 || m.status[0].name != kName) return false;
  const msg::DiagnosticStatus& d = m.status[0];
  std::map<std::string, std::string> v;
  for (const auto& kv : d.values) v[kv.key] = kv.value;
  PlannerStatus s;
  if (!time.to_utime(m.header.stamp_ns, s.utime)) return false;
  s.planner = d.hardware_id;
  s.reason = v["reason"];
  bool known = false;
  for (int i = 0; i <= static_cast<int>(core::PlannerState::kFailed); ++i) {
    if (v["state"] == core::to_string(static_cast<core::PlannerState>(i))) {
      s.state = i;
      known = true;
    }
  }
  int64_t iteration = 0, nodes = 0, edges = 0;
  double gx = 0, gy = 0, gz = 0;
  const bool ok = known && parse_int(v["iteration"], iteration) && parse_int(v["num_nodes"], nodes) &&
                  parse_int(v["num_edges"], edges) && parse_double(v["goal_x"], gx) && parse_double(v["goal_y"], gy) &&
                  parse_double(v["goal_z"], gz) && parse_double(v["best_gain"], s.best_gain) &&
                  parse_double(v["best_reward"], s.best_reward) && parse_double(v["best_score"], s.best_score) &&
                  parse_double(v["total_ms"], s.total_ms) && parse_double(v["charged_s"], s.charged_s);
  if (!ok) return false;
  s.iteration = iteration;
  s.num_nodes = static_cast<int>(nodes);
  s.num_edges = static_cast<int>(edges);
  s.goal = {gx, gy, gz};
  out = std::move(s);
  return true;
}

}  // namespace semx::rosbridge
