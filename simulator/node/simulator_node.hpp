// The simulator process: drives the Simulator library from the clock and publishes its sensors
// over LCM (DESIGN.md §1, §3). Each tick it steps physics up to the tick's time, publishes every
// sensor sample that fell due (IMU, odometry, camera frames, events), and only then SIM_CLOCK, so
// a node that handled SIM_CLOCK(k) has seen all data up to k. In LOCKSTEP the next tick waits for
// the registered nodes' acks; with none registered the simulation runs as fast as it can. Before
// its first tick the simulator waits until it has heard every registered node report itself
// running (NODE_STATUS): a node that subscribed late would miss the initial frame and events,
// which the clock's resent ticks do not repeat, and a run would depend on start-up timing (a
// launcher's fixed delay used to stand in for this; a loaded machine could outlast it).
#pragma once

#include <semx/control_cmd_t.hpp>

#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "semx/runtime/bus_listeners.hpp"
#include "semx/runtime/clock_server.hpp"
#include "semx/runtime/image_codec.hpp"
#include "semx/runtime/node.hpp"
#include "semx/runtime/state_file.hpp"
#include "semx/simulator/simulator.hpp"

namespace semx::simulator {

struct SimulatorNodeOptions {
  runtime::ClockServerConfig clock;  // period_us is the tick; max_ticks ends the episode
  // Payload codecs. Labels and RGB are piecewise constant: run-length coding cuts them ~20x,
  // and bytes through loopback are what limit the lockstep speed. Depth stays raw by default.
  runtime::ImageCompression depth_codec = runtime::ImageCompression::kNone;
  runtime::ImageCompression label_codec = runtime::ImageCompression::kRle;
  runtime::ImageCompression rgb_codec = runtime::ImageCompression::kRle;
  // RGB as runs: the same image and payload, without an image to write and scan.
  unsigned render_channels = kRenderDepth | kRenderLabels | kRenderRgbRuns;
  double progress_every_s = 10.0;  // simulated seconds between progress lines (0: none)
  // Wall seconds to wait for the registered nodes before starting without the silent ones (named
  // on stderr; in LOCKSTEP the clock still waits for their acks).
  double ready_timeout_s = 30.0;
  // LOCKSTEP: before each new tick, wait up to this many wall seconds for readers of the port
  // that are not the set's (a stock lcm-logger started by hand) to take what was sent
  // (runtime/bus_listeners.hpp); 0: never wait. Costs nothing while no such reader listens.
  double foreign_hold_s = 0.1;
  // Where to save the simulation's state every tick (empty: nowhere), and whether to resume from
  // what is there (a restart after a crash): the episode then goes on from the last tick
  // published, which is sent again, never an earlier one (docs/launch.md, "When a process dies").
  std::string state_path;
  bool resume = false;
};

class SimulatorNode {
 public:
  SimulatorNode(Simulator& sim, runtime::Node& node, SimulatorNodeOptions options);

  // Runs until the episode ends (max_ticks) or shutdown; returns the exit code.
  int run();
  // One pass of the loop at wall time `wall_s`: handles commands, publishes a tick if one is due.
  // Returns false once the episode is over.
  bool poll(double wall_s);

  int64_t ticks() const { return server_.current_tick() + 1; }
  int64_t frames_published() const { return frames_; }
  int64_t commands_rejected() const { return rejected_; }
  // Every registered node was heard (or the wait timed out); true at once with none registered.
  bool ready() const { return ready_; }
  // The tick it resumed at (-1: it started the episode).
  int64_t resumed_at() const { return resumed_at_; }

 private:
  void advance_to(int64_t utime);
  void publish_frame();
  void publish_clock(const runtime::ClockTick& t);
  void publish_event(int8_t type, const std::string& text, const Eigen::Vector3d& where, int solid,
                     int64_t count);
  void on_command(const semx::control_cmd_t& m);
  // Before the first tick: whether to start now (everyone heard, or the wait timed out).
  bool check_ready(double wall_s);
  void save_state(int64_t tick);
  void restore_state(const std::vector<uint8_t>& bytes, double wall_s);

  Simulator& sim_;
  runtime::Node& node_;
  SimulatorNodeOptions options_;
  runtime::ClockServer server_;
  CameraFrame frame_;
  bool started_ = false;
  int64_t frames_ = 0;
  int64_t rejected_ = 0;
  double next_progress_s_ = 0;
  double wall_start_ = -1;
  bool ready_ = true;
  double wait_start_ = -1;
  std::set<std::string> heard_;  // registered nodes heard running
  std::unique_ptr<runtime::StateSlot> state_;
  std::vector<uint8_t> state_bytes_;
  int64_t resumed_at_ = -1;
  std::unique_ptr<runtime::BusListeners> listeners_;  // LOCKSTEP on udpm with foreign_hold_s > 0
};

}  // namespace semx::simulator
