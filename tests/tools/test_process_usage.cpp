// The launcher's exit line carries what a process cost; the bench report reads it back.
#include <gtest/gtest.h>

#include "semx/tools/process_usage.hpp"

namespace semx::tools {
namespace {

TEST(ProcessUsage, TheExitLineReadsBackWhatWasWritten) {
  const std::string line = "[semx-launch] mapper: exited with 0" + usage_text({123.4, 15.66, 1.64});
  EXPECT_EQ(line, "[semx-launch] mapper: exited with 0 (peak RSS 123 MB, CPU 15.7 s user + 1.6 s system)");
  const auto got = parse_exit_line(line);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->first, "mapper");
  EXPECT_DOUBLE_EQ(got->second.peak_rss_mb, 123.0);
  EXPECT_DOUBLE_EQ(got->second.cpu_s(), 15.7 + 1.6);
  // A process killed by a signal (its label, as the launcher prints it) is read the same way.
  const auto killed =
      parse_exit_line("[semx-launch] ros_bridge: killed by signal Killed" + usage_text({9, 1, 2}));
  ASSERT_TRUE(killed);
  EXPECT_EQ(killed->first, "ros_bridge");
  EXPECT_DOUBLE_EQ(killed->second.system_s, 2.0);
}

TEST(ProcessUsage, OtherLinesAndOlderExitLinesGiveNothing) {
  EXPECT_FALSE(parse_exit_line("[semx-launch] mapper: started (pid 12)"));
  EXPECT_FALSE(
      parse_exit_line("[semx-launch] mapper: exited with 0 (peak RSS 123 MB)"));  // before CPU figures
  EXPECT_FALSE(parse_exit_line("mapper: exited with 0 (peak RSS 1 MB, CPU 1.0 s user + 1.0 s system)"));
  EXPECT_FALSE(
      parse_exit_line("[semx-launch] : exited with 0 (peak RSS 1 MB, CPU 1.0 s user + 1.0 s system)"));
  EXPECT_FALSE(parse_exit_line(""));
}

}  // namespace
}  // namespace semx::tools
