// semx-hostile: publishes malformed messages (truncated, oversized, negative or huge array
// lengths, wrong fingerprints, noise, bit flips) on a channel, to prove that the processes
// listening count and drop them and stay alive. For tests and for anyone hardening a node.
#include <chrono>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/wire_generator.hpp"

using namespace semx::runtime;

int main(int argc, char** argv) {
  return run_main("semx-hostile", [&] {
    NodeFlags flags("hostile");
    std::string channel, type_name, kinds = "all";
    int64_t count = 10, seed = 1;
    double rate = 200;
    bool unsigned_ = false;
    ArgParser p("semx-hostile", "Publishes malformed messages on a channel (testing tool).");
    flags.add_to(p);
    p.option("channel", "NAME", "channel to attack (required)", &channel)
        .option("type", "TYPE", "type to corrupt (default: the channel's type, e.g. semx.path_t)", &type_name)
        .option("kinds", "K1,K2",
                "truncated, oversized, negative-length, huge-length, wrong-fingerprint, "
                "random-bytes, bit-flip, or all (default)",
                &kinds)
        .option("count", "N", "messages per kind (default 10)", &count)
        .option("rate", "HZ", "messages per second (default 200)", &rate)
        .option("seed", "N", "random seed (default 1)", &seed)
        .flag("unsigned",
              "send without the set's trailer, as a process without its key would (every node drops them "
              "before decoding); by default they are signed, so the nodes' decoders and checks see them",
              &unsigned_);
    if (!p.parse(argc, argv)) return 0;
    if (channel.empty()) throw ArgError("--channel is required");
    if (!(rate > 0)) throw ArgError("--rate must be positive");
    if (type_name.empty()) type_name = std::string(semx::channels::type_of(channel));
    if (type_name.empty()) throw ArgError("--channel " + channel + " is not a semx channel: give --type");
    const auto& schema = LcmSchema::semx();
    const LcmStruct* type = schema.find(type_name);
    if (!type) throw ArgError("--type: unknown type '" + type_name + "'");

    std::vector<HostileKind> selected;
    std::stringstream ss(kinds);
    for (std::string k; std::getline(ss, k, ',');) {
      bool found = false;
      for (auto kind : all_hostile_kinds()) {
        if (k == "all" || k == to_string(kind)) {
          selected.push_back(kind);
          found = true;
        }
      }
      if (!found) throw ArgError("--kinds: unknown kind '" + k + "'");
    }

    auto options = flags.options();
    options.follow_clock = false;
    options.sign = !unsigned_;
    Node node(options);
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    const auto period = std::chrono::duration<double>(1.0 / rate);
    int64_t sent = 0;
    for (auto kind : selected) {
      for (int64_t i = 0; i < count; ++i) {
        const auto bytes = hostile_wire_message(schema, *type, kind, rng);
        if (node.publish_raw(channel, bytes.data(), bytes.size())) ++sent;
        std::this_thread::sleep_for(period);
      }
    }
    std::cout << "semx-hostile: sent " << sent << " malformed " << type->full_name() << " messages on "
              << channel << "\n";
    return 0;
  });
}
