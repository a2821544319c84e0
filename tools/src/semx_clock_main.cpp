// semx-clock: a source of simulation time without a simulator (DESIGN.md §3). Drives nodes in
// REALTIME or LOCKSTEP for tests, log replays and bring-up; the simulator embeds the same
// ClockServer.
#include <semx/ack_t.hpp>
#include <semx/clock_t.hpp>

#include <iostream>
#include <sstream>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/clock_server.hpp"
#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/node_flags.hpp"

using namespace semx::runtime;

namespace {

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-clock", [&] {
    NodeFlags flags("clock");
    std::string mode = "realtime", nodes;
    double period_ms = 10, speed = 1, max_speed = 0, resend_s = 0.05, stall_warn_s = 5;
    int64_t ticks = -1;
    ArgParser p("semx-clock",
                "Publishes SIM_CLOCK. LOCKSTEP advances only when every --lockstep-nodes node acked.");
    flags.add_to(p);
    p.option("mode", "realtime|lockstep", "clock mode (default realtime)", &mode)
        .option("period-ms", "MS", "simulated milliseconds per tick (default 10)", &period_ms)
        .option("speed", "X", "REALTIME: simulated seconds per wall second (default 1)", &speed)
        .option("lockstep-nodes", "A,B", "LOCKSTEP: nodes that must ack every tick", &nodes)
        .option("max-speed", "X", "LOCKSTEP: at most X simulated seconds per wall second (default: no cap)",
                &max_speed)
        .option("ticks", "N", "exit after N ticks (default: run until stopped)", &ticks)
        .option("resend", "S", "LOCKSTEP: resend an unacked tick after S wall seconds (default 0.05)",
                &resend_s)
        .option("stall-warn", "S", "LOCKSTEP: report nodes that keep the clock waiting longer (default 5)",
                &stall_warn_s);
    if (!p.parse(argc, argv)) return 0;
    if (mode != "realtime" && mode != "lockstep")
      throw ArgError("--mode: '" + mode + "' is not realtime or lockstep");
    if (!(period_ms > 0)) throw ArgError("--period-ms must be positive");
    if (!(speed > 0)) throw ArgError("--speed must be positive");

    ClockServerConfig cfg;
    cfg.mode = mode == "lockstep" ? ClockMode::kLockstep : ClockMode::kRealtime;
    cfg.period_us = static_cast<int64_t>(period_ms * 1000.0);
    cfg.speed = speed;
    cfg.max_speed = max_speed;
    cfg.lockstep_nodes = split_list(nodes);
    cfg.resend_after_s = resend_s;
    cfg.max_ticks = ticks;
    if (cfg.mode == ClockMode::kLockstep && cfg.lockstep_nodes.empty()) {
      throw ArgError("--mode lockstep needs --lockstep-nodes (who to wait for)");
    }
    ClockServer server(cfg);

    auto options = flags.options();
    options.follow_clock = false;  // it is the clock
    Node node(options);
    install_shutdown_handlers();
    node.subscribe<semx::ack_t>(semx::channels::SIM_ACK,
                                [&](const semx::ack_t& a) { server.on_ack(a.node, a.tick, a.quiet_until); });
    node.set_state(NodeState::kRunning, mode);
    std::cout << "semx-clock: " << mode << ", " << period_ms << " ms/tick"
              << (cfg.mode == ClockMode::kLockstep ? ", waiting for " + nodes : "") << " on " << node.url()
              << "\n";

    bool warned = false;
    while (!node.stopped() && !server.finished()) {
      const double now = semx::runtime::monotonic_s();
      if (auto t = server.poll(now, node.holds_everything())) {
        semx::clock_t c{};
        c.utime = t->utime;
        c.tick = t->tick;
        c.mode = static_cast<int8_t>(cfg.mode);
        c.speed = cfg.mode == ClockMode::kRealtime ? cfg.speed : 0.0;
        c.period_us = cfg.period_us;
        node.set_time(t->utime, t->tick, cfg.mode);
        node.publish(semx::channels::SIM_CLOCK, c);
        if (!t->resend) warned = false;
      }
      if (cfg.mode == ClockMode::kLockstep && !warned && server.seconds_waiting(now) > stall_warn_s) {
        std::string who;
        for (const auto& n : server.waiting_for()) who += (who.empty() ? "" : ", ") + n;
        std::cerr << "semx-clock: tick " << server.current_tick() << " waiting " << stall_warn_s
                  << " s for: " << who << "\n";
        node.set_state(NodeState::kDegraded, "waiting for " + who);
        warned = true;
      } else if (!warned && node.state() == NodeState::kDegraded) {
        node.set_state(NodeState::kRunning, mode);
      }
      if (node.spin_once(1) < 0) return 1;
    }
    node.drain();
    node.set_state(server.finished() ? NodeState::kDone : NodeState::kStopping,
                   "tick " + std::to_string(server.current_tick()));
    std::cout << "semx-clock: stopped at tick " << server.current_tick()
              << " (t = " << server.current_utime() * 1e-6 << " s)\n";
    return 0;
  });
}
