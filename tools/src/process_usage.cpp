#include "semx/tools/process_usage.hpp"

#include <cstdio>
#include <cstring>

namespace semx::tools {

std::string usage_text(const ProcessUsage& u) {
  char text[96];
  std::snprintf(text, sizeof text, " (peak RSS %.0f MB, CPU %.1f s user + %.1f s system)", u.peak_rss_mb,
                u.user_s, u.system_s);
  return text;
}

std::optional<std::pair<std::string, ProcessUsage>> parse_exit_line(const std::string& line) {
  static const std::string kHead = "[semx-launch] ";
  const std::size_t head = line.find(kHead);
  if (head == std::string::npos) return std::nullopt;
  const std::size_t name_at = head + kHead.size();
  const std::size_t colon = line.find(": ", name_at);
  if (colon == std::string::npos || colon == name_at) return std::nullopt;
  const std::string rest = line.substr(colon + 2);
  if (rest.rfind("exited with ", 0) != 0 && rest.rfind("killed by signal ", 0) != 0) return std::nullopt;
  const std::size_t open = rest.find(" (peak RSS ");
  if (open == std::string::npos) return std::nullopt;
  ProcessUsage u;
  if (std::sscanf(rest.c_str() + open, " (peak RSS %lf MB, CPU %lf s user + %lf s system)", &u.peak_rss_mb,
                  &u.user_s, &u.system_s) != 3) {
    return std::nullopt;
  }
  return std::make_pair(line.substr(name_at, colon - name_at), u);
}

}  // namespace semx::tools
