// The flags every semx process shares, so `--lcm-url`, `--name` and `--lockstep` mean the same
// thing everywhere and the launcher can pass them blindly.
#pragma once

#include <string>

#include "semx/runtime/args.hpp"
#include "semx/runtime/node.hpp"

namespace semx::runtime {

struct NodeFlags {
  std::string name;
  std::string lcm_url;
  bool lockstep = false;
  double status_period_s = 1.0;
  bool quiet = false;
  std::string auth_key_file;

  explicit NodeFlags(std::string default_name) : name(std::move(default_name)) {}

  void add_to(ArgParser& p) {
    p.option("name", "NAME", "node name in NODE_STATUS and SIM_ACK (default: " + name + ")", &name)
        .option("lcm-url", "URL", "LCM provider (default: $LCM_DEFAULT_URL, else loopback udpm)", &lcm_url)
        .flag("lockstep", "ack every SIM_CLOCK tick: the clock waits for this node", &lockstep)
        .option("status-period", "S", "NODE_STATUS heartbeat period in wall seconds (default 1)",
                &status_period_s)
        .flag("quiet", "do not log dropped or malformed messages", &quiet)
        .option("auth-key", "FILE",
                "the set's key (64 hex digits; default: $SEMX_AUTH_KEY or $SEMX_AUTH_KEY_FILE, which the "
                "launcher sets; without any, the open session that only processes without a key share)",
                &auth_key_file);
  }

  NodeOptions options() const {
    if (!(status_period_s > 0)) throw ArgError("--status-period must be positive");
    NodeOptions o;
    o.name = name;
    o.lcm_url = lcm_url;
    o.lockstep = lockstep;
    o.status_period_s = status_period_s;
    o.quiet = quiet;
    o.auth_key_file = auth_key_file;
    o.announce = true;  // processes started together by a launcher find each other at once
    return o;
  }
};

}  // namespace semx::runtime
