// Where a process talks: the LCM provider URL.
#pragma once

#include <string>

namespace semx::runtime {

// Loopback-only (ttl=0: nothing leaves the host) with a receive buffer large enough that 1 MB
// camera frames at 30 Hz are not dropped by the kernel (DESIGN.md §6).
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

// The flag's value if given, else $LCM_DEFAULT_URL, else kDefaultLcmUrl; with_receive_buffer().
std::string resolve_lcm_url(const std::string& flag_value);

// A udpm URL without recv_buf_size gets 4 MB: liblcm programs the launcher starts (lcm-logger)
// would otherwise take the kernel's default, and a mapper given such a URL integrated 406 of 1149
// depth frames of an env3 run. Other URLs are returned as they are.
std::string with_receive_buffer(const std::string& url);

// A loopback udpm URL on its own port, so tests running in parallel do not hear each other.
std::string udpm_url_for_port(int port);

}  // namespace semx::runtime
