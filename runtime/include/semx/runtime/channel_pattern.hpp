// A channel pattern as liblcm takes it: a POSIX extended regular expression that must match the
// whole name. Matching runs per message in pattern subscribers (the monitor, the logger), so each
// name's answer is kept; the names seen are bounded (a flood of made-up names only clears it).
#pragma once

#include <regex>
#include <string>
#include <unordered_map>

namespace semx::runtime {

class ChannelPattern {
 public:
  // Throws std::invalid_argument naming the pattern when it is not a regular expression.
  explicit ChannelPattern(const std::string& pattern);

  bool matches(const std::string& channel) const;
  const std::string& text() const { return text_; }

 private:
  static constexpr std::size_t kMaxRemembered = 1024;
  std::string text_;
  std::regex regex_;
  mutable std::unordered_map<std::string, bool> seen_;
};

}  // namespace semx::runtime
