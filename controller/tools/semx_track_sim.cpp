// semx-track-sim: the controller flying the simulator's vehicle model (issue 7's tracking
// figure). Both libraries run in one loop on simulated time (1 ms physics, 100 Hz control) in an
// empty room, so the figure is the tracking of the dynamics, not of obstacle avoidance. One
// 'name: value unit' line per figure.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "semx/controller/controller.hpp"
#include "semx/controller/distance_field.hpp"
#include "semx/runtime/args.hpp"
#include "semx/simulator/simulator.hpp"
#include "semx/simulator/world.hpp"

namespace ctl = semx::controller;
namespace sim = semx::simulator;

namespace {

// An empty room's interior, far from every wall along the test paths.
class OpenSpace : public ctl::DistanceField {
 public:
  double distance(const Eigen::Vector3d&, Eigen::Vector3d* gradient) const override {
    if (gradient) gradient->setZero();
    return 5.0;
  }
  double lipschitz() const override { return 1.0; }
};

sim::World room(double sx, double sy, double sz) {
  sim::World w;
  w.name = "open-room";
  const double t = 0.2;
  w.bounds = {{-t, -t, -t}, {sx + t, sy + t, sz + t}};
  w.start.position = {1.0, 1.0, 1.2};
  using C = semx::runtime::SemanticClass;
  w.solids.push_back(sim::Solid::box(C::kFloor, {sx / 2, sy / 2, -t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(sim::Solid::box(C::kCeiling, {sx / 2, sy / 2, sz + t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(sim::Solid::box(C::kWall, {-t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(sim::Solid::box(C::kWall, {sx + t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(sim::Solid::box(C::kWall, {sx / 2, -t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  w.solids.push_back(sim::Solid::box(C::kWall, {sx / 2, sy + t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  return w;
}

struct Flight {
  double rms = 0, max_error = 0, seconds = 0, mean_speed = 0;
  int64_t collisions = 0;
};

Flight fly(const std::vector<Eigen::Vector3d>& waypoints, double speed) {
  sim::SimulatorConfig scfg;
  sim::Simulator s(room(12, 12, 3), scfg);
  ctl::ControllerConfig ccfg;
  ccfg.limits.max_velocity = speed;
  ctl::Controller c(ccfg);
  auto field = std::make_shared<OpenSpace>();
  ctl::Path path;
  path.plan_id = 1;
  path.waypoints = waypoints;
  path.yaws.assign(waypoints.size(), 0.0);
  Flight f;
  double err_sq = 0, dist = 0;
  int64_t samples = 0, flying_us = 0;
  bool started = false, done = false;
  Eigen::Vector3d last = s.odometry().position;
  while (!done && s.time_us() < 120'000'000) {
    s.step();
    if (s.time_us() % 10000 != 0) continue;  // 100 Hz control
    const auto o = s.odometry();
    const int64_t now = s.time_us();
    if (now % 100000 == 0) c.on_esdf(field, now);
    ctl::VehicleState st;
    st.utime = now;
    st.position = o.position;
    st.velocity = o.velocity;
    st.yaw =
        std::atan2(2 * (o.orientation.w() * o.orientation.z() + o.orientation.x() * o.orientation.y()),
                   1 - 2 * (o.orientation.y() * o.orientation.y() + o.orientation.z() * o.orientation.z()));
    c.on_odometry(st);
    if (!started && now >= 200000) {
      path.utime = now;
      c.on_path(path);
      started = true;
    }
    const ctl::StepOutput out = c.step(now);
    if (out.command.mode == ctl::Command::Mode::kVelocity) {
      s.command(sim::ControlCommand::velocity_yaw(out.command.velocity, out.command.yaw));
    } else {
      s.command(sim::ControlCommand{});
    }
    if (const ctl::Trajectory* traj = c.trajectory()) {
      const double t = static_cast<double>(now - traj->start_utime) * 1e-6;
      if (t >= 0 && t <= traj->duration()) {
        const double e = (traj->position.evaluate(t, 0) - o.position).norm();
        err_sq += e * e;
        f.max_error = std::max(f.max_error, e);
        ++samples;
        flying_us += 10000;
        dist += (o.position - last).norm();
      }
      done = started && t > traj->duration() + 0.5;
    }
    last = o.position;
  }
  f.rms = samples ? std::sqrt(err_sq / static_cast<double>(samples)) : -1;
  f.seconds = static_cast<double>(flying_us) * 1e-6;
  f.mean_speed = f.seconds > 0 ? dist / f.seconds : 0;
  f.collisions = s.vehicle().collisions();
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  return semx::runtime::run_main("semx-track-sim", [&] {
    double speed = 1.0;
    semx::runtime::ArgParser p(
        "semx-track-sim",
        "Flies the controller on the simulator's vehicle model and prints the tracking error.");
    p.option("speed", "M/S", "speed limit (default 1.0)", &speed);
    if (!p.parse(argc, argv)) return 0;
    const std::vector<std::pair<const char*, std::vector<Eigen::Vector3d>>> paths = {
        {"square_6m", {{1, 1, 1.2}, {7, 1, 1.2}, {7, 7, 1.2}, {1, 7, 1.2}, {1, 1, 1.2}}},
        {"zigzag_climb", {{1, 1, 1.2}, {4, 3, 1.6}, {2, 6, 1.0}, {6, 8, 2.0}, {10, 10, 1.2}}},
        {"straight_10m", {{1, 1, 1.2}, {11, 1, 1.2}}},
    };
    for (const auto& [name, wps] : paths) {
      const Flight f = fly(wps, speed);
      std::printf("%s_tracking_rms: %.3f m\n", name, f.rms);
      std::printf("%s_tracking_max: %.3f m\n", name, f.max_error);
      std::printf("%s_mean_speed: %.2f m/s\n", name, f.mean_speed);
      std::printf("%s_collisions: %lld\n", name, static_cast<long long>(f.collisions));
    }
    return 0;
  });
}
