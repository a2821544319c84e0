// Which channels a recorder keeps: a pattern, as lcm-logger's --channel takes it (a POSIX
// extended regular expression that must match the whole name), optionally inverted.
#pragma once

#include <string>
#include <vector>

#include "semx/runtime/channel_pattern.hpp"

namespace semx::tools {

class ChannelSelection {
 public:
  // Throws std::invalid_argument naming the pattern when it is not a regular expression.
  ChannelSelection(const std::string& pattern, bool invert) : pattern_(pattern), invert_(invert) {}

  bool wants(const std::string& channel) const;
  // The channels of semx (channels.hpp) this selection refuses, for the kernel to drop before
  // the recorder reads them; channels semx does not know are refused by wants() alone.
  std::vector<std::string> refused_known() const;

 private:
  runtime::ChannelPattern pattern_;
  bool invert_;
};

}  // namespace semx::tools
