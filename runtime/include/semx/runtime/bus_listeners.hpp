// Readers of a set's udpm port that are not the set's: a liblcm program a user starts by hand
// (lcm-logger, lcm-spy). They do not ack ticks, so a lockstep clock would run past them, and
// they hold little: the kernel's default receive buffer (416 KiB) and liblcm's queue of 30
// messages, which its main thread empties. Whatever they have not taken when more comes is
// dropped without a word. The lockstep clock asks caught_up() before each new tick: every such
// reader's socket is empty and none of its threads is runnable (a liblcm reader whose queue
// holds a message is awake to dispatch it). Linux only: it reads /proc (this network namespace's
// sockets; the processes of this user, or all as root).
#pragma once

#include <sys/types.h>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace semx::runtime {

struct UdpSocketInfo {
  uint64_t inode = 0;
  uint32_t rx_queue = 0;  // bytes not yet read
  uint64_t drops = 0;     // datagrams the kernel dropped at this socket
};

// The UDP sockets bound to `port` listed in `table` (the text of /proc/net/udp).
std::vector<UdpSocketInfo> udp_sockets_on_port(const std::string& table, int port);

// SEMX_FOREIGN_HOLD (wall seconds, default 0.1; 0: never wait for foreign readers): what the
// lockstep clock and every sender use for max_hold_s. Throws std::runtime_error naming the
// variable when it is not a non-negative number.
double foreign_hold_from_env();

// What a foreign reader's socket may hold before a sender waits: a quarter of the kernel's
// default receive buffer (net.core.rmem_default). The kernel's own count, against which it drops,
// can be up to another quarter above what /proc/net/udp shows (memory the reader has taken and
// not yet given back), and a 64 KB fragment (about 65 KB to the kernel) must fit on top.
uint32_t foreign_room_bytes();

class BusListeners {
 public:
  // `own_exe_dir`: processes whose executable is in this folder are the set's (semx's nodes read
  // their socket on a thread of their own and take part in lockstep); every other is foreign.
  // `max_hold_s`: the longest caught_up() says false in a row, so that a foreign process that
  // never sleeps (busy on something else) slows the set down but never stops it.
  BusListeners(int port, std::string own_exe_dir, double max_hold_s = 0.1, double rescan_s = 0.5,
               std::string proc = "/proc");

  // True when no foreign reader is behind (or none reads the port), or after max_hold_s of false.
  bool caught_up(double wall_s);

  // True when every foreign reader's socket holds less than `max_queued` bytes (or none reads
  // the port), or after max_hold_s of false: room for another datagram.
  bool has_room(double wall_s, uint32_t max_queued);

  const std::vector<pid_t>& foreign() const { return pids_; }
  int64_t holds() const { return holds_; }      // caught_up() calls that said false
  int64_t gave_up() const { return gave_up_; }  // times max_hold_s ran out

 private:
  void rescan();
  // Refreshes who reads the port (every rescan_s); the sockets on it when it read them.
  std::vector<UdpSocketInfo> refresh(double wall_s, bool* read);
  bool hold(double wall_s, bool behind);

  int port_;
  std::string own_exe_dir_;
  double max_hold_s_;
  double rescan_s_;
  std::string proc_;
  double next_scan_s_ = -1;
  double holding_since_s_ = -1;
  std::set<uint64_t> inodes_;  // every socket on the port at the last scan
  std::set<uint64_t> foreign_inodes_;
  std::vector<pid_t> pids_;
  int64_t holds_ = 0;
  int64_t gave_up_ = 0;
};

}  // namespace semx::runtime
