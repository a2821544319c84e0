#include "semx/runtime/bus_pacer.hpp"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace semx::runtime {

std::optional<BusPace> parse_bus_pace(const std::string& text) {
  BusPace p;
  if (text.empty()) return p;
  std::vector<double> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ':')) {
    if (part.empty()) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (end != part.c_str() + part.size() || !(x >= 0) || x > 1e6) return std::nullopt;
    v.push_back(x);
  }
  if (v.empty() || v.size() > 3 || text.back() == ':') return std::nullopt;
  p.bytes_per_s = v[0] * 1e6;
  if (p.bytes_per_s <= 0) return BusPace{};
  // Half the 416 KiB a default liblcm reader holds, so that small messages behind a burst fit.
  p.burst_bytes = v.size() > 1 ? v[1] * 1e3 : 200e3;
  p.datagram_bytes = v.size() > 2 ? v[2] * 1e3 : 0;
  // A burst smaller than one datagram would never let a 65 KB fragment through at once.
  p.burst_bytes = std::max(p.burst_bytes, 65536.0);
  return p;
}

BusPace bus_pace_from_env() {
  const char* env = std::getenv("SEMX_BUS_PACE");
  if (!env) return {};
  if (auto p = parse_bus_pace(env)) return *p;
  throw std::runtime_error(std::string("SEMX_BUS_PACE='") + env +
                           "': expected MB_PER_S[:BURST_KB[:DATAGRAM_KB]], e.g. 40:200");
}

BusPacer::BusPacer(BusPace pace) : pace_(pace), tokens_(pace.burst_bytes) {}

double BusPacer::delay(std::size_t bytes, double now_s) {
  if (!active()) return 0;
  if (last_s_ >= 0 && now_s > last_s_)
    tokens_ = std::min(pace_.burst_bytes, tokens_ + (now_s - last_s_) * pace_.bytes_per_s);
  last_s_ = std::max(last_s_, now_s);
  tokens_ -= std::max(static_cast<double>(bytes), pace_.datagram_bytes);
  return tokens_ >= 0 ? 0.0 : -tokens_ / pace_.bytes_per_s;
}

}  // namespace semx::runtime
