#include "semx/runtime/channel_pattern.hpp"

#include <stdexcept>

namespace semx::runtime {

ChannelPattern::ChannelPattern(const std::string& pattern) : text_(pattern) {
  try {
    regex_ = std::regex(pattern, std::regex::extended);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("channel pattern '" + pattern + "' is not a regular expression: " + e.what());
  }
}

bool ChannelPattern::matches(const std::string& channel) const {
  const auto it = seen_.find(channel);
  if (it != seen_.end()) return it->second;
  if (seen_.size() >= kMaxRemembered) seen_.clear();
  const bool m = std::regex_match(channel, regex_);
  seen_.emplace(channel, m);
  return m;
}

}  // namespace semx::runtime
