#include "semx/tools/channel_selection.hpp"

#include <stdexcept>

#include "semx/runtime/channels.hpp"

namespace semx::tools {

ChannelSelection::ChannelSelection(const std::string& pattern, bool invert) : invert_(invert) {
  try {
    pattern_ = std::regex(pattern, std::regex::extended);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("channel pattern '" + pattern + "' is not a regular expression: " + e.what());
  }
}

bool ChannelSelection::wants(const std::string& channel) const {
  return std::regex_match(channel, pattern_) != invert_;
}

std::vector<std::string> ChannelSelection::refused_known() const {
  std::vector<std::string> out;
  for (const auto& c : channels::kAll) {
    const std::string name(c.channel);
    if (!wants(name)) out.push_back(name);
  }
  return out;
}

}  // namespace semx::tools
