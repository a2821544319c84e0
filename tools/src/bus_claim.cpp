#include "semx/tools/bus_claim.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "semx/runtime/udpm_receiver.hpp"

namespace semx::tools {

namespace {

// Anything at all on the group and port within listen_s: a live set sends its clock, heartbeats
// and frames many times a second.
bool talking(const runtime::UdpmEndpoint& e, double listen_s) {
  runtime::UdpmEndpoint quiet = e;
  quiet.recv_buf_size = 0;
  runtime::UdpmReceiver r(quiet, 1u << 20);
  r.filter({}, true);
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(listen_s);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    if (r.wait(static_cast<int>(left.count()))) return true;
  }
}

int lock_port(const BusClaimOptions& o, const runtime::UdpmEndpoint& e) {
  // One directory for every user, like /tmp itself, so one user's set keeps another's off its port.
  const mode_t old = umask(0);
  mkdir(o.lock_dir.c_str(), 01777);
  const std::string file = o.lock_dir + "/" + e.group + "-" + std::to_string(e.port) + ".lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  umask(old);
  if (fd < 0) return -2;  // no lock directory: listening alone decides
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

std::string with_port(const std::string& url, int port) {
  const std::size_t q = url.find('?');
  const std::string address = url.substr(0, q);
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos) return url;
  return address.substr(0, colon + 1) + std::to_string(port) + (q == std::string::npos ? "" : url.substr(q));
}

BusClaim claim_bus(const std::string& url, const BusClaimOptions& o) {
  BusClaim c;
  c.url = url;
  auto e = runtime::parse_udpm_url(url);
  if (!e) return c;
  c.requested_port = c.port = e->port;
  const PortPolicy policy = e->ttl > 0 && o.policy == PortPolicy::kMove ? PortPolicy::kRefuse : o.policy;
  for (int k = 0; k <= o.max_moves && e->port + k <= 65535; ++k) {
    runtime::UdpmEndpoint at = *e;
    at.port = e->port + k;
    const int fd = lock_port(o, at);
    std::string why;
    if (fd == -1) {
      why = "another semx set on this host holds port " + std::to_string(at.port);
    } else if (talking(at, o.listen_s)) {
      why = "something already talks on port " + std::to_string(at.port);
    }
    if (why.empty() || policy == PortPolicy::kShare) {
      c.port = at.port;
      c.lock_fd = fd >= 0 ? fd : -1;
      c.url = with_port(url, at.port);
      c.shared = why;
      return c;
    }
    if (fd >= 0) ::close(fd);
    if (k == 0) c.why_moved = why;
    if (policy == PortPolicy::kRefuse) {
      throw std::runtime_error(why + (e->ttl > 0 ? " (a multi-host URL, ttl > 0, never moves to another port)" : "") +
                               "; stop that set, choose another port, or --port-policy share");
    }
  }
  throw std::runtime_error("no free LCM port from " + std::to_string(e->port) + " to " +
                           std::to_string(e->port + o.max_moves));
}

}  // namespace semx::tools
