#include "simulator_node.hpp"

#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/sim_event_t.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/executable_dir.hpp"
#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/udpm_receiver.hpp"
#include "simulator_messages.hpp"

namespace semx::simulator {

namespace ch = semx::channels;

namespace {
constexpr uint32_t kStateKind = runtime::state_kind("SIMS");
}  // namespace

SimulatorNode::SimulatorNode(Simulator& sim, runtime::Node& node, SimulatorNodeOptions options)
    : sim_(sim), node_(node), options_(std::move(options)), server_(options_.clock) {
  node_.subscribe<semx::control_cmd_t>(
      ch::CONTROL_CMD, [this](const semx::control_cmd_t& m) { on_command(m); }, &well_formed);
  node_.subscribe<semx::ack_t>(ch::SIM_ACK, [this](const semx::ack_t& a) {
    server_.on_ack(a.node, a.tick, a.quiet_until, semx::runtime::monotonic_s());
  });
  next_progress_s_ = options_.progress_every_s;
  if (options_.clock.mode == runtime::ClockMode::kLockstep && options_.foreign_hold_s > 0 &&
      node_.own_receiver()) {
    if (const auto e = runtime::parse_udpm_url(node_.url()))
      listeners_ = std::make_unique<runtime::BusListeners>(e->port, runtime::executable_dir(),
                                                           options_.foreign_hold_s);
  }
  if (!options_.state_path.empty()) {
    // Read before the slot is opened, which empties the file.
    const auto saved = options_.resume ? runtime::read_state_slot(options_.state_path, kStateKind)
                                       : std::optional<std::vector<uint8_t>>();
    if (saved) restore_state(*saved, semx::runtime::monotonic_s());
    state_ = std::make_unique<runtime::StateSlot>(options_.state_path, kStateKind);
  }
  const auto& nodes = options_.clock.lockstep_nodes;
  if (!nodes.empty() && resumed_at_ < 0) {
    ready_ = false;
    node_.subscribe<semx::node_status_t>(ch::NODE_STATUS, [this](const semx::node_status_t& s) {
      const auto& want = options_.clock.lockstep_nodes;
      const bool up = s.state == static_cast<int8_t>(runtime::NodeState::kRunning) ||
                      s.state == static_cast<int8_t>(runtime::NodeState::kDegraded);
      if (up && std::find(want.begin(), want.end(), s.node) != want.end()) heard_.insert(s.node);
    });
  }
}

void SimulatorNode::save_state(int64_t tick) {
  state_bytes_.clear();
  core::ByteWriter w(state_bytes_);
  w.i64(tick);
  w.i64(frames_);
  w.i64(rejected_);
  w.f64(next_progress_s_);
  const std::vector<uint8_t> sim = sim_.save_state();
  w.bytes(sim.data(), sim.size());
  state_->write(state_bytes_);
}

void SimulatorNode::restore_state(const std::vector<uint8_t>& bytes, double wall_s) {
  core::ByteReader r(bytes.data(), bytes.size());
  int64_t tick = 0;
  try {
    tick = r.i64();
    frames_ = r.i64();
    rejected_ = r.i64();
    next_progress_s_ = r.f64();
  } catch (const std::out_of_range&) {
    throw runtime::StateFileError(options_.state_path + ": truncated simulator state");
  }
  const std::size_t header = bytes.size() - r.remaining();
  try {
    sim_.restore_state(
        std::vector<uint8_t>(bytes.begin() + static_cast<std::ptrdiff_t>(header), bytes.end()));
  } catch (const std::runtime_error& e) {
    throw runtime::StateFileError(options_.state_path + ": " + e.what());
  }
  // The episode started long ago: no start event, no initial frame, no waiting for the nodes
  // (they are running; the resent tick reaches whoever listens).
  started_ = true;
  server_.resume(tick, wall_s);
  resumed_at_ = tick;
}

bool SimulatorNode::check_ready(double wall_s) {
  if (wait_start_ < 0) wait_start_ = wall_s;
  std::vector<std::string> missing;
  for (const std::string& n : options_.clock.lockstep_nodes) {
    if (!heard_.count(n)) missing.push_back(n);
  }
  if (missing.empty()) return ready_ = true;
  if (wall_s - wait_start_ < options_.ready_timeout_s) return false;
  std::string names;
  for (const std::string& n : missing) names += (names.empty() ? "" : ", ") + n;
  std::fprintf(stderr, "semx-simulator: starting without a NODE_STATUS from %s after %.0f s\n", names.c_str(),
               options_.ready_timeout_s);
  return ready_ = true;
}

void SimulatorNode::on_command(const semx::control_cmd_t& m) {
  const CommandResult r = sim_.command(from_message(m));
  if (!r.accepted) {
    ++rejected_;
    publish_event(semx::sim_event_t::COMMAND_REJECTED, r.reason, sim_.odometry().position, -1, rejected_);
  }
}

void SimulatorNode::publish_event(int8_t type, const std::string& text, const Eigen::Vector3d& where,
                                  int solid, int64_t count) {
  semx::sim_event_t e{};
  e.utime = sim_.time_us();
  e.type = type;
  e.description = text;
  for (int i = 0; i < 3; ++i) e.position[i] = where[i];
  e.solid_index = solid;
  e.count = count;
  node_.publish(ch::SIM_EVENT, e);
}

void SimulatorNode::publish_frame() {
  sim_.render_camera(frame_, options_.render_channels);
  if (frame_.channels & kRenderDepth)
    node_.publish(ch::CAMERA_DEPTH, depth_message(frame_, options_.depth_codec));
  if (frame_.channels & (kRenderRgb | kRenderRgbRuns))
    node_.publish(ch::CAMERA_RGB, rgb_message(frame_, options_.rgb_codec));
  if (frame_.channels & kRenderLabels)
    node_.publish(ch::CAMERA_LABELS, label_message(frame_, options_.label_codec));
  ++frames_;
}

void SimulatorNode::advance_to(int64_t utime) {
  if (!started_) {
    // Tick 0 carries the initial state, so the map starts from the first view, not 33 ms later.
    started_ = true;
    publish_event(semx::sim_event_t::EPISODE_START, sim_.world().name, sim_.odometry().position, -1, 1);
    node_.publish(ch::ODOMETRY, to_message(sim_.odometry()));
    publish_frame();
  }
  while (sim_.time_us() < utime) {
    const StepResult r = sim_.step();
    if (r.imu) node_.publish(ch::IMU, to_message(*r.imu));
    if (r.odometry) node_.publish(ch::ODOMETRY, to_message(*r.odometry));
    if (r.collision) {
      publish_event(semx::sim_event_t::COLLISION, "body box hit a solid", r.collision->position,
                    r.collision->solid, r.collision->count);
    }
    if (r.camera_due) publish_frame();
  }
}

void SimulatorNode::publish_clock(const runtime::ClockTick& t) {
  semx::clock_t c{};
  c.utime = t.utime;
  c.tick = t.tick;
  c.mode = static_cast<int8_t>(options_.clock.mode);
  c.speed = options_.clock.mode == runtime::ClockMode::kRealtime ? options_.clock.speed : 0.0;
  c.period_us = options_.clock.period_us;
  node_.set_time(t.utime, t.tick, options_.clock.mode);
  node_.publish(ch::SIM_CLOCK, c);
}

bool SimulatorNode::poll(double wall_s) {
  node_.drain();
  if (!ready_ && !check_ready(wall_s)) return true;
  if (wall_start_ < 0) wall_start_ = wall_s;
  if (server_.finished()) return false;
  // A command an ack named but that was lost on the way is asked for again before the next
  // tick: the vehicle must fly the run a lossless bus gives.
  // A reader outside the set (a stock lcm-logger) is asked only when the tick is otherwise due.
  const bool held = node_.holds_everything() &&
                    (!listeners_ || !server_.waiting_for().empty() || listeners_->caught_up(wall_s));
  if (auto t = server_.poll(wall_s, held)) {
    if (!t->resend) {
      advance_to(t->utime);
      // Saved before the tick goes out: a simulator killed after this resends this tick, one
      // killed before it steps to it again from the last (its sensors' outputs then twice).
      if (state_) save_state(t->tick);
    }
    publish_clock(*t);
    if (!t->resend) server_.mark_published(semx::runtime::monotonic_s());
    const double sim_s = static_cast<double>(t->utime) * 1e-6;
    if (options_.progress_every_s > 0 && sim_s >= next_progress_s_) {
      const auto o = sim_.odometry();
      std::printf(
          "semx-simulator: t=%.1f s  pos=(%.2f, %.2f, %.2f)  frames=%lld  collisions=%lld  %.1fx real time\n",
          sim_s, o.position.x(), o.position.y(), o.position.z(), static_cast<long long>(frames_),
          static_cast<long long>(sim_.vehicle().collisions()), sim_s / std::max(1e-9, wall_s - wall_start_));
      next_progress_s_ += options_.progress_every_s;
    }
  }
  return !server_.finished();
}

int SimulatorNode::run() {
  node_.set_state(runtime::NodeState::kRunning, sim_.world().name);
  const bool lockstep = options_.clock.mode == runtime::ClockMode::kLockstep;
  while (!node_.stopped()) {
    const double now = semx::runtime::monotonic_s();
    if (!poll(now)) break;
    // Lockstep with acks to wait for, or realtime between ticks: sleep in LCM until something
    // arrives (an ack, a command) or 1 ms passes. Lockstep with nobody to wait for: no sleep.
    if (!lockstep || !options_.clock.lockstep_nodes.empty()) {
      if (node_.spin_once(1) < 0) return 1;
    }
  }
  const double wall = semx::runtime::monotonic_s() - wall_start_;
  const double sim_s = static_cast<double>(sim_.time_us()) * 1e-6;
  if (server_.finished()) {
    publish_event(semx::sim_event_t::EPISODE_END, "time limit", sim_.odometry().position, -1, 1);
    node_.set_state(runtime::NodeState::kDone, "episode ended");
  }
  std::printf(
      "semx-simulator: simulated %.2f s in %.2f s wall (%.1fx real time), %lld frames, %lld collisions, "
      "%lld commands rejected\n",
      sim_s, wall, sim_s / std::max(1e-9, wall), static_cast<long long>(frames_),
      static_cast<long long>(sim_.vehicle().collisions()), static_cast<long long>(rejected_));
  if (listeners_ && listeners_->holds() > 0) {
    // A reader outside the set (a stock lcm-logger) was waited for: the run was slower for it.
    std::printf("semx-simulator: waited %lld times for readers of the port outside the set (pids",
                static_cast<long long>(listeners_->holds()));
    for (pid_t pid : listeners_->foreign()) std::printf(" %d", static_cast<int>(pid));
    std::printf("), %lld of them cut short after %.2f s\n", static_cast<long long>(listeners_->gave_up()),
                options_.foreign_hold_s);
  }
  if (lockstep && !server_.waited_on().empty()) {
    // Whom the clock waited on: the node whose ack completed each tick, and for how long.
    std::vector<std::pair<double, std::string>> w;
    double total = 0;
    for (const auto& [name, s] : server_.waited_on()) {
      w.emplace_back(s, name);
      total += s;
    }
    std::sort(w.rbegin(), w.rend());
    std::printf("semx-simulator: lockstep: %.2f s of the %.2f s wall waiting for acks; completed by", total,
                wall);
    for (const auto& [s, name] : w) std::printf(" %s %.2f s,", name.c_str(), s);
    std::printf(" the rest in the simulator\n");
  }
  return 0;
}

}  // namespace semx::simulator
