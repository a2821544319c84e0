// semx-monitor: every node's NODE_STATUS and every channel's traffic, in the terminal.
// A tool that starts late learns the whole state by listening (DESIGN.md §1). With --expect it
// doubles as a readiness check for scripts: exit 0 once the named nodes run, 1 on --timeout.
#include <semx/node_status_t.hpp>

#include <cstdio>
#include <iostream>
#include <sstream>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_schema.hpp"
#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/wire_validator.hpp"
#include "semx/tools/status_board.hpp"

using namespace semx::runtime;

namespace {}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-monitor", [&] {
    NodeFlags flags("monitor");
    double interval = 1.0, timeout = 0, duration = 0;
    std::string expect;
    bool channels = false, once = false;
    ArgParser p("semx-monitor", "Prints every node's NODE_STATUS and, with --channels, per-channel traffic.");
    flags.add_to(p);
    p.option("interval", "S", "seconds between reports (default 1)", &interval)
        .option("expect", "A,B", "exit 0 as soon as these nodes report and are not stopping/failed", &expect)
        .option("timeout", "S", "with --expect: exit 1 if they have not all reported after S seconds",
                &timeout)
        .option("duration", "S", "exit 0 after S seconds", &duration)
        .flag("channels", "also show messages, rate, bandwidth and malformed count per channel", &channels)
        .flag("once", "print one report (after --interval) and exit", &once);
    if (!p.parse(argc, argv)) return 0;
    if (!(interval > 0)) throw ArgError("--interval must be positive");
    std::vector<std::string> expected;
    std::stringstream ss(expect);
    for (std::string n; std::getline(ss, n, ',');) {
      if (!n.empty()) expected.push_back(n);
    }

    auto options = flags.options();
    options.observer = true;
    Node node(options);
    install_shutdown_handlers();
    semx::tools::StatusBoard board;
    node.subscribe<semx::node_status_t>(semx::channels::NODE_STATUS, [&](const semx::node_status_t& s) {
      board.on_status(s, semx::runtime::monotonic_s());
    });
    if (channels) {
      // Validate every known channel's bytes as they pass, independent of any subscriber.
      const auto& schema = LcmSchema::semx();
      node.subscribe_raw(".*", [&](const std::string& channel, const uint8_t* data, std::size_t size) {
        const auto type_name = semx::channels::type_of(channel);
        const LcmStruct* type = type_name.empty() ? nullptr : schema.find(type_name);
        const bool bad =
            type && validate_wire(schema, *type, schema.fingerprint(*type), data, size) != WireError::kNone;
        board.on_message(channel, size, bad);
      });
    }
    node.set_state(NodeState::kRunning);

    const double start = semx::runtime::monotonic_s();
    board.update_rates(start);
    double next_report = start + interval;
    while (!node.stopped()) {
      if (node.spin_once(50) < 0) return 1;
      const double now = semx::runtime::monotonic_s();
      if (!expected.empty() && board.missing(expected).empty()) {
        std::cout << board.render_nodes(now) << "semx-monitor: all expected nodes are up\n";
        return 0;
      }
      if (now >= next_report) {
        board.update_rates(now);
        char head[96];
        std::snprintf(head, sizeof head, "--- %zu nodes, %.1f s ---\n", board.nodes().size(), now - start);
        std::cout << head << board.render_nodes(now);
        if (channels) std::cout << board.render_channels();
        std::cout.flush();
        next_report = now + interval;
        if (once) return 0;
      }
      if (!expected.empty() && timeout > 0 && now - start > timeout) {
        std::string who;
        for (const auto& n : board.missing(expected)) who += (who.empty() ? "" : ", ") + n;
        std::cerr << "semx-monitor: timed out after " << timeout << " s waiting for: " << who << "\n";
        return 1;
      }
      if (duration > 0 && now - start > duration) return 0;
    }
    return 0;
  });
}
