#include "semx/runtime/lcm_url.hpp"

#include <cstdlib>

namespace semx::runtime {

std::string resolve_lcm_url(const std::string& flag_value) {
  std::string url = flag_value;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = env && *env ? env : kDefaultLcmUrl;
  }
  return with_receive_buffer(url);
}

std::string with_receive_buffer(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0) return url;
  const std::size_t q = url.find('?');
  if (q != std::string::npos && ("&" + url.substr(q + 1)).find("&recv_buf_size=") != std::string::npos) return url;
  return url + (q == std::string::npos ? "?" : "&") + "recv_buf_size=4194304";
}

std::string udpm_url_for_port(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
}

}  // namespace semx::runtime
