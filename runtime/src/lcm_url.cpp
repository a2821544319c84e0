#include "semx/runtime/lcm_url.hpp"

#include <cstdlib>

namespace semx::runtime {

std::string resolve_lcm_url(const std::string& flag_value) {
  if (!flag_value.empty()) return flag_value;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (env && *env) return env;
  return kDefaultLcmUrl;
}

std::string udpm_url_for_port(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
}

}  // namespace semx::runtime
