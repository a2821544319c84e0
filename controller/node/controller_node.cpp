#include "controller_node.hpp"

#include <cmath>
#include <iostream>
#include <memory>

#include "controller_messages.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::controller {

ControllerNode::ControllerNode(runtime::NodeOptions options, const ControllerConfig& config)
    : config_(config), node_(std::move(options)), controller_(config) {
  node_.subscribe<semx::path_t>(
      semx::channels::PLAN_PATH, [this](const semx::path_t& m) { controller_.on_path(to_path(m)); },
      accept_path);
  node_.judges_non_finite(semx::channels::PLAN_PATH);  // a bad path is answered REJECTED
  const OutsideWindow outside =
      config_.clearance.outside_is_obstacle ? OutsideWindow::kObstacle : OutsideWindow::kFree;
  node_.subscribe<semx::esdf_local_t>(
      semx::channels::ESDF_LOCAL,
      [this, outside](const semx::esdf_local_t& m) {
        controller_.on_esdf(std::make_shared<GridDistanceField>(to_distance_field(m, outside)), m.utime);
      },
      accept_esdf);
  node_.subscribe<semx::odometry_t>(
      semx::channels::ODOMETRY,
      [this](const semx::odometry_t& m) { controller_.on_odometry(to_vehicle_state(m)); }, accept_odometry);
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  // The controller publishes only on its control steps, so the clock need not wait for it on the
  // ticks between them (rate_hz below the clock's tick rate). At the tick rate this promises
  // nothing: the next step is the next tick.
  node_.on_quiet_until([this](int64_t utime) {
    if (last_step_utime_ < 0 || last_step_utime_ > utime) return utime;
    return last_step_utime_ + step_period_us() - 1;
  });
  node_.set_state(runtime::NodeState::kRunning, "waiting for inputs");
}

void ControllerNode::on_tick(int64_t /*tick*/, int64_t utime) {
  if (utime < last_step_utime_) {
    // The clock restarted (a new episode): nothing from the old one applies.
    controller_.reset();
    last_step_utime_ = last_status_utime_ = -1;
  }
  // Run at rate_hz of simulation time whatever the clock's tick period (1 µs of slack for
  // periods that do not divide evenly into microseconds).
  if (last_step_utime_ >= 0 && utime - last_step_utime_ < step_period_us() - 1) return;
  last_step_utime_ = utime;

  const StepOutput out = controller_.step(utime);
  node_.publish(semx::channels::CONTROL_CMD, to_message(out.command, utime));
  if (out.new_trajectory) node_.publish(semx::channels::TRAJECTORY, to_message(*out.new_trajectory, utime));
  const int64_t status_period = static_cast<int64_t>(std::llround(1e6 / config_.status_rate_hz));
  if (out.status_changed || last_status_utime_ < 0 || utime - last_status_utime_ >= status_period - 1) {
    publish_status(out.status, utime);
  }
  if (out.status_changed) {
    update_node_state();
    // Rejections and brakes in the log (RUN/logs/controller.log): the only place their reason is
    // readable after a run, and the first thing to look at when the vehicle stops moving. Rare
    // events (one per path at most), so they are logged even with --quiet, which is about drops.
    const ControllerState st = out.status.state;
    if (st == ControllerState::kRejected || st == ControllerState::kBraking) {
      std::cerr << "semx-controller: t=" << static_cast<double>(utime) * 1e-6 << " s " << to_string(st) << " "
                << out.status.reason << std::endl;
    }
  }
}

int ControllerNode::run() {
  const int code = node_.run();
  const ControllerCounters& c = controller_.counters();
  std::cout << "semx-controller: paths " << c.paths << ", trajectories " << c.trajectories << " (optimised "
            << c.optimized << " (slowed " << c.slowed << ", of them near one place or a few only "
            << c.slowed_near << "), fallback " << c.fallbacks << ": strayed " << c.fallback_strays
            << ", too close " << c.fallback_too_close << "), squared headings " << c.squared_headings
            << ", repaired headings " << c.repaired_headings << ", rejected " << c.rejected << ", unsafe "
            << c.unsafe << ", brakes " << c.brakes << ", stale stops " << c.stale_stops << ", off track "
            << c.off_track << std::endl;
  return code;
}

int64_t ControllerNode::step_period_us() const {
  return static_cast<int64_t>(std::llround(1e6 / config_.rate_hz));
}

void ControllerNode::publish_status(const ControllerStatus& s, int64_t utime) {
  node_.publish(semx::channels::CONTROLLER_STATUS, to_message(s, utime));
  last_status_utime_ = utime;
}

void ControllerNode::update_node_state() {
  const ControllerStatus& s = controller_.status();
  const ControllerCounters& c = controller_.counters();
  const std::string detail = std::string(to_string(s.state)) + " plan " + std::to_string(s.plan_id) +
                             "; trajectories " + std::to_string(c.trajectories) + " (fallback " +
                             std::to_string(c.fallbacks) + "), rejected " +
                             std::to_string(c.rejected + c.unsafe) + ", brakes " + std::to_string(c.brakes);
  node_.set_state(
      s.state == ControllerState::kStaleInput ? runtime::NodeState::kDegraded : runtime::NodeState::kRunning,
      detail);
}

}  // namespace semx::controller
