// A set's own bus. Two sets on one LCM port used to run on each other's clock (an office bench
// run fell from 91.8 % to 25.6 % coverage while a demo shared its port). Messages are now tagged
// with their set's session (runtime/message_auth.hpp), so sets on one port ignore each other;
// the launcher still gives each set a port of its own, so that no set spends its time reading
// and refusing another's camera frames:
//  - on this host, a set holds an advisory lock on its port for its whole life (two launchers
//    started together cannot both take one port);
//  - a port where anything talks (a set of another user, a liblcm program) is busy too;
//  - the launcher then moves to the next free port and says so, or refuses (ttl > 0: the hosts
//    of a multi-host set must agree on the port, so it never moves).
#pragma once

#include <string>

namespace semx::tools {

enum class PortPolicy {
  kMove,    // take the next free port, and say so
  kRefuse,  // fail when the port is busy
  kShare,   // use the port even when busy (sessions still keep the sets apart)
};

struct BusClaim {
  std::string url;        // the URL the set uses
  int requested_port = 0;
  int port = 0;
  std::string why_moved;  // why the requested port was not taken (empty: it was)
  std::string shared;     // kShare: why the port taken is busy (empty: it is not)
  int lock_fd = -1;       // held until the launcher exits (O_CLOEXEC: children do not hold it)
};

struct BusClaimOptions {
  PortPolicy policy = PortPolicy::kMove;
  double listen_s = 0.3;  // how long a port must be silent to count as free
  int max_moves = 64;
  std::string lock_dir = "/tmp/semx-ports";
};

// Throws std::runtime_error when no port can be claimed. URLs that are not udpm are returned
// as they are (no lock, no listening).
BusClaim claim_bus(const std::string& url, const BusClaimOptions& options = {});

// The URL with its port replaced.
std::string with_port(const std::string& udpm_url, int port);

}  // namespace semx::tools
