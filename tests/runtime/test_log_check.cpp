// semx-log-check, what ./semx replay runs before lcm-logplayer: a whole log passes, a log cut
// inside its last event passes with a note, anything else fails with exit 1 and the reason.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string output;
};

Result check(const std::string& log) {
  const std::string cmd = std::string(SEMX_BIN_DIR) + "/semx-log-check " + log + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[512];
  while (p && fgets(buf, sizeof buf, p)) r.output += buf;
  const int rc = p ? pclose(p) : -1;
  r.code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

std::string write_log(const std::string& dir, int events) {
  const std::string path = dir + "/run.lcmlog";
  lcm::LogFile log(path, "w");
  std::vector<uint8_t> data(100, 7);
  for (int i = 0; i < events; ++i) {
    lcm::LogEvent e;
    e.eventnum = i;
    e.timestamp = 1000 * i;
    e.channel = "ODOMETRY";
    e.datalen = static_cast<int32_t>(data.size());
    e.data = data.data();
    log.writeEvent(&e);
  }
  return path;
}

TEST(LogCheck, WholeCutAndCorruptLogs) {
  const std::string dir = (fs::temp_directory_path() / ("semx_log_check_" + std::to_string(getpid()))).string();
  fs::create_directories(dir);
  const std::string log = write_log(dir, 3);
  Result r = check(log);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("3 events"), std::string::npos) << r.output;

  // The logger killed while writing: the last event is cut, the rest is a log.
  const auto size = fs::file_size(log);
  fs::copy_file(log, dir + "/cut.lcmlog");
  fs::resize_file(dir + "/cut.lcmlog", size - 20);
  r = check(dir + "/cut.lcmlog");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("cut short"), std::string::npos) << r.output;

  // The second event's header overwritten (each event: a 28-byte header, the channel, the data):
  // exit 1 with the byte offset.
  fs::copy_file(log, dir + "/bad.lcmlog");
  {
    std::fstream f(dir + "/bad.lcmlog", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 3));
    const std::string junk(40, 'x');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  }
  r = check(dir + "/bad.lcmlog");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("bad.lcmlog"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(std::to_string(size / 3)), std::string::npos) << r.output;

  std::ofstream(dir + "/text.lcmlog") << "not a log";
  EXPECT_EQ(check(dir + "/text.lcmlog").code, 1);
  EXPECT_EQ(check(dir + "/missing.lcmlog").code, 1);
  fs::remove_all(dir);
}

}  // namespace
