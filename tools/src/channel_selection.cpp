#include "semx/tools/channel_selection.hpp"

#include "semx/runtime/channels.hpp"

namespace semx::tools {

bool ChannelSelection::wants(const std::string& channel) const {
  return pattern_.matches(channel) != invert_;
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
