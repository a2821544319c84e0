// semx-hostile: publishes hostile messages on a channel, to prove that the processes listening
// count and drop them, stay alive and change nothing of the run. Two axes:
//  - what the bytes are (--kinds): malformed (truncated, oversized, negative or huge array
//    lengths, wrong fingerprints, noise, bit flips), or decodable but wrong in value (NaN and
//    infinite fields; extreme integers such as utime INT64_MAX, a far-future tick, the enum
//    values that mean DONE, EPISODE_END or COLLISION);
//  - who sends them (--as): the set itself (insider: signed with its key, so the decoders and the
//    nodes' own checks see them), a process without the key (unsigned), another set (foreign),
//    or a copy of the set's own messages sent again (replay) or altered (tamper).
// For tests, tests/integration/hostile_campaign.sh, and anyone hardening a node.
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/message_auth.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/wire_generator.hpp"

using namespace semx::runtime;

namespace {

enum class Sender { kInsider, kUnsigned, kForeign, kReplay, kTamper };

Sender parse_sender(const std::string& s) {
  if (s == "insider") return Sender::kInsider;
  if (s == "unsigned") return Sender::kUnsigned;
  if (s == "foreign") return Sender::kForeign;
  if (s == "replay") return Sender::kReplay;
  if (s == "tamper") return Sender::kTamper;
  throw ArgError("--as '" + s + "': expected insider, unsigned, foreign, replay or tamper");
}

std::vector<HostileKind> parse_kinds(const std::string& kinds) {
  std::vector<HostileKind> selected;
  std::stringstream ss(kinds);
  for (std::string k; std::getline(ss, k, ',');) {
    std::vector<HostileKind> candidates = all_hostile_kinds();
    for (auto d : decodable_hostile_kinds()) candidates.push_back(d);
    bool found = false;
    for (auto kind : candidates) {
      const bool malformed = kind != HostileKind::kNonFinite && kind != HostileKind::kExtreme;
      if ((k == "all" && malformed) || k == "every" || k == to_string(kind)) {
        selected.push_back(kind);
        found = true;
      }
    }
    if (!found) throw ArgError("--kinds: unknown kind '" + k + "'");
  }
  return selected;
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-hostile", [&] {
    NodeFlags flags("hostile");
    std::string channel, type_name, kinds = "all", as = "insider";
    int64_t count = 10, seed = 1;
    double rate = 200, capture_s = 30;
    bool unsigned_ = false, list = false;
    ArgParser p("semx-hostile", "Publishes hostile messages on a channel (testing tool).");
    flags.add_to(p);
    p.option("channel", "NAME", "channel to attack (required)", &channel)
        .option("type", "TYPE", "type to corrupt (default: the channel's type, e.g. semx.path_t)", &type_name)
        .option("kinds", "K1,K2",
                "malformed: truncated, oversized, negative-length, huge-length, wrong-fingerprint, "
                "random-bytes, bit-flip, or all of these (default); decodable but wrong: non-finite "
                "(NaN/inf fields; skipped for types without real fields), extreme; every: all nine",
                &kinds)
        .option("count", "N", "messages per kind (default 10); replay and tamper: messages in all", &count)
        .option("rate", "HZ", "messages per second (default 200)", &rate)
        .option("seed", "N", "random seed (default 1)", &seed)
        .option("as", "SENDER",
                "insider (default: signed with the set's key, so the nodes' decoders and checks see "
                "them), unsigned (a process without the key), foreign (signed with a key of its own, "
                "as another set), replay (the set's own messages on the channel, captured and sent "
                "again unchanged; needs the set's key to pick them out, as a sniffer would), tamper "
                "(captured, one payload byte changed, the trailer kept)",
                &as)
        .option("capture-timeout", "S", "replay, tamper: wall seconds to wait for a message to copy (default 30)",
                &capture_s)
        .flag("unsigned", "the same as --as unsigned", &unsigned_)
        .flag("list", "print semx's channels and their types, one per line, and exit", &list);
    if (!p.parse(argc, argv)) return 0;
    if (list) {
      for (const auto& c : semx::channels::kAll) std::cout << c.channel << " " << c.type << "\n";
      return 0;
    }
    if (channel.empty()) throw ArgError("--channel is required");
    if (!(rate > 0)) throw ArgError("--rate must be positive");
    if (count < 0) throw ArgError("--count must not be negative");
    const Sender sender = unsigned_ ? Sender::kUnsigned : parse_sender(as);
    const bool copies = sender == Sender::kReplay || sender == Sender::kTamper;
    if (type_name.empty()) type_name = std::string(semx::channels::type_of(channel));
    if (type_name.empty() && !copies) throw ArgError("--channel " + channel + " is not a semx channel: give --type");
    const auto& schema = LcmSchema::semx();
    const LcmStruct* type = copies ? nullptr : schema.find(type_name);
    if (!copies && !type) throw ArgError("--type: unknown type '" + type_name + "'");
    const std::vector<HostileKind> selected = parse_kinds(kinds);

    auto options = flags.options();
    options.follow_clock = false;
    options.observer = true;  // it is owed nothing of the set's past
    options.sign = sender == Sender::kInsider || sender == Sender::kForeign;
    if (sender == Sender::kForeign) {
      options.auth_key_file.clear();
      setenv("SEMX_AUTH_KEY", AuthKey::random().hex().c_str(), 1);
    }
    Node node(options);
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    const auto period = std::chrono::duration<double>(1.0 / rate);
    int64_t sent = 0;

    if (copies) {
      // The set's messages as they came, trailer and all: sent unsigned, they go out byte for byte.
      std::vector<std::vector<uint8_t>> captured;
      node.subscribe_raw(
          channel,
          [&](const std::string&, const uint8_t* data, std::size_t size) {
            if (captured.size() < 64) captured.emplace_back(data, data + size);
          },
          true);
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(capture_s);
      while (captured.empty() && std::chrono::steady_clock::now() < give_up && !node.stopped()) node.spin_once(50);
      if (captured.empty()) {
        std::cerr << "semx-hostile: no message of the set on " << channel << " within " << capture_s
                  << " s to " << as << "\n";
        return 1;
      }
      for (int64_t i = 0; i < count && !node.stopped(); ++i) {
        node.spin_once(0);
        std::vector<uint8_t> bytes = captured[static_cast<std::size_t>(i) % captured.size()];
        if (sender == Sender::kTamper && bytes.size() > kAuthTrailerBytes) {
          bytes[rng() % (bytes.size() - kAuthTrailerBytes)] ^= static_cast<uint8_t>(1 + rng() % 255);
        }
        if (node.publish_raw(channel, bytes.data(), bytes.size())) ++sent;
        std::this_thread::sleep_for(period);
      }
      std::cout << "semx-hostile: sent " << sent << " " << as << "ed copies of " << captured.size()
                << " captured messages on " << channel << "\n";
      return 0;
    }

    for (auto kind : selected) {
      if (kind == HostileKind::kNonFinite && !has_real_field(schema, *type)) continue;
      for (int64_t i = 0; i < count && !node.stopped(); ++i) {
        const auto bytes = hostile_wire_message(schema, *type, kind, rng);
        if (node.publish_raw(channel, bytes.data(), bytes.size())) ++sent;
        node.spin_once(0);  // its own heartbeat; and a set's resend requests are not for it
        std::this_thread::sleep_for(period);
      }
    }
    std::cout << "semx-hostile: sent " << sent << " hostile " << type->full_name() << " messages on " << channel
              << " as " << (unsigned_ ? "unsigned" : as) << "\n";
    return 0;
  });
}
