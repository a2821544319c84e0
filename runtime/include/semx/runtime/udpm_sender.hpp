// Publishes on an LCM udpm group in liblcm's wire format (lcm_datagram.hpp), with one addition
// the format leaves room for: the sequence number, which receivers only use to tell a sender's
// messages apart, carries a tag of the channel. Fragments after the first name no channel, so
// without the tag a kernel filter (udpm_receiver.hpp) could not drop them, and every process
// received every fragment of every camera frame and ESDF window.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "semx/runtime/bus_listeners.hpp"
#include "semx/runtime/bus_pacer.hpp"
#include "semx/runtime/udpm_receiver.hpp"

namespace semx::runtime {

// The seqno's layout is in lcm_datagram.hpp (kSeqnoTagged): liblcm's senders' fragments stay
// untagged and always pass the filter.
// A 20-bit hash of the name, never 0. Two channels with one tag would let each other's later
// fragments through a filter that wants one of them, or drop them in one that refuses one of
// them (semx's own channels have distinct tags, a test checks).
uint32_t channel_tag(const std::string& channel);

class UdpmSender {
 public:
  // Throws std::runtime_error naming the endpoint and the failing call. `pace`: every datagram
  // waits for its turn (bus_pacer.hpp); by default what SEMX_BUS_PACE says, i.e. none.
  // `foreign_hold_s` > 0: every datagram waits, up to that long, until every reader of the port
  // outside the set (a stock lcm-logger) has room for it (bus_listeners.hpp).
  explicit UdpmSender(const UdpmEndpoint& endpoint, BusPace pace = bus_pace_from_env(),
                      double foreign_hold_s = foreign_hold_from_env());
  ~UdpmSender();
  UdpmSender(const UdpmSender&) = delete;
  UdpmSender& operator=(const UdpmSender&) = delete;

  // Sends one message as one datagram or as fragments; false when the name is not a channel
  // liblcm could carry or the kernel refused a datagram. `*seqno`, when given, is the seqno it
  // went with (what publish_again() needs).
  bool publish(const std::string& channel, const uint8_t* data, std::size_t size, uint32_t* seqno = nullptr);
  // Sends a message published before again, byte for byte: a fragmented one as SXR3 fragments
  // under its first seqno (lcm_datagram.hpp), so readers join them with the fragments they hold;
  // a one-datagram one as a new message.
  bool publish_again(const std::string& channel, const uint8_t* data, std::size_t size, uint32_t seqno);

  // How often a datagram found a reader outside the set without room and waited (one count per
  // look, every 200 us); 0 with no such reader.
  int64_t waits() const { return listeners_ ? listeners_->holds() : 0; }

  // The largest datagram this sender writes (liblcm reads up to 64 KiB).
  static constexpr std::size_t kMaxDatagram = 65000;

 private:
  bool send_message(const std::string& channel, const uint8_t* data, std::size_t size, uint32_t seqno,
                    uint32_t fragment_magic);

  int fd_ = -1;
  BusPacer pacer_;
  std::unique_ptr<BusListeners> listeners_;
  uint32_t foreign_room_ = 0;
  std::vector<uint8_t> header_;
  uint8_t counter_ = 0;
  uint32_t group_ = 0;  // network order
  uint16_t port_ = 0;   // network order
};

}  // namespace semx::runtime
