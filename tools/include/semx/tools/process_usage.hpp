// What a process of a set cost: the launcher's exit line carries it ("(peak RSS 123 MB, CPU
// 15.7 s user + 1.6 s system)") and the bench report reads it back from each run's launch.log,
// so the text is written and parsed here only.
#pragma once
#include <optional>
#include <string>
#include <utility>

namespace semx::tools {

struct ProcessUsage {
  double peak_rss_mb = 0;
  double user_s = 0;
  double system_s = 0;
  double cpu_s() const { return user_s + system_s; }
};

// " (peak RSS 123 MB, CPU 15.7 s user + 1.6 s system)", the tail of the exit line.
std::string usage_text(const ProcessUsage& u);

// A launcher line "[semx-launch] NAME: exited with CODE (peak RSS ...)" or "... killed by signal
// ... (peak RSS ...)": the process's name and usage. Anything else, or an exit line from before
// the CPU figures, gives nothing.
std::optional<std::pair<std::string, ProcessUsage>> parse_exit_line(const std::string& line);

}  // namespace semx::tools
