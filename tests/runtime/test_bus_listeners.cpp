// Readers of the port outside the set (bus_listeners.hpp), on a /proc made here: which
// processes are foreign, when they have caught up, and that a reader that never sleeps only
// slows the set down.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "semx/runtime/bus_listeners.hpp"

using namespace semx::runtime;
namespace fs = std::filesystem;

namespace {

const char* kHeader =
    "   sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref "
    "pointer drops\n";

std::string udp_line(int port, unsigned rx_queue, unsigned long inode, unsigned long drops = 0) {
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      " 2243: 00000000:%04X 00000000:0000 07 00000000:%08X 00:00000000 00000000     0        0 %lu 2 "
      "00000000fb493afc %lu\n",
      port, rx_queue, inode, drops);
  return buf;
}

// A /proc with a set's mapper (socket 11), a stock lcm-logger (socket 22, threads 200 and 201)
// and a process on another port (socket 33).
class FakeProc {
 public:
  FakeProc() : root_(fs::path(::testing::TempDir()) / ("semx_proc_" + std::to_string(getpid()))) {
    fs::remove_all(root_);
    fs::create_directories(root_ / "net");
    process(100, "/opt/semx/bin/semx-mapper", 11, {{100, 'S'}});
    process(200, "/usr/bin/lcm-logger", 22, {{200, 'S'}, {201, 'S'}});
    process(300, "/usr/bin/other", 33, {{300, 'R'}});
    table(0);
  }
  ~FakeProc() { fs::remove_all(root_); }
  std::string path() const { return root_.string(); }
  void table(unsigned stock_rx_queue) {
    std::ofstream(root_ / "net" / "udp")
        << kHeader << udp_line(7667, 0, 11) << udp_line(7667, stock_rx_queue, 22) << udp_line(7668, 0, 33);
  }
  void thread(int pid, int tid, char state) {
    std::ofstream(root_ / std::to_string(pid) / "task" / std::to_string(tid) / "stat")
        << tid << " (lcm-logger (x)) " << state << " 1 2 3\n";
  }

 private:
  void process(int pid, const std::string& exe, unsigned long inode,
               std::vector<std::pair<int, char>> threads) {
    const fs::path p = root_ / std::to_string(pid);
    fs::create_directories(p / "fd");
    fs::create_symlink("socket:[" + std::to_string(inode) + "]", p / "fd" / "3");
    fs::create_symlink("/dev/null", p / "fd" / "0");
    fs::create_symlink(exe, p / "exe");
    for (const auto& [tid, state] : threads) {
      fs::create_directories(p / "task" / std::to_string(tid));
      thread(pid, tid, state);
    }
  }
  fs::path root_;
};

}  // namespace

TEST(BusListeners, ReadsTheSocketsOnAPort) {
  const std::string table = std::string(kHeader) + udp_line(7667, 0x1234, 42, 17) + udp_line(7668, 0, 43, 5) +
                            udp_line(7667, 0, 44) + "garbage line\n";
  const auto s = udp_sockets_on_port(table, 7667);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].inode, 42u);
  EXPECT_EQ(s[0].rx_queue, 0x1234u);
  EXPECT_EQ(s[0].drops, 17u);  // decimal, unlike the queues
  EXPECT_EQ(s[1].inode, 44u);
  EXPECT_EQ(s[1].drops, 0u);
  EXPECT_TRUE(udp_sockets_on_port("", 7667).empty());
}

TEST(BusListeners, WaitsForAForeignReaderToCatchUp) {
  FakeProc proc;
  BusListeners l(7667, "/opt/semx/bin", 0.1, 0.5, proc.path());
  EXPECT_TRUE(l.caught_up(0.0));
  ASSERT_EQ(l.foreign(), std::vector<pid_t>{200});  // not the set's mapper, not the other port's
  // A thread of the reader runnable: it has messages to dispatch.
  proc.thread(200, 201, 'R');
  EXPECT_FALSE(l.caught_up(0.01));
  proc.thread(200, 201, 'S');
  EXPECT_TRUE(l.caught_up(0.02));
  // Bytes in its socket: not caught up; room for a large datagram only below the mark.
  proc.table(0x30000);
  EXPECT_FALSE(l.caught_up(0.03));
  EXPECT_FALSE(l.has_room(0.04, 0x20000));
  proc.table(0x1000);
  EXPECT_TRUE(l.has_room(0.05, 0x20000));
  EXPECT_FALSE(l.caught_up(0.06));
  proc.table(0);
  EXPECT_TRUE(l.caught_up(0.07));
  EXPECT_EQ(l.gave_up(), 0);
}

TEST(BusListeners, AReaderThatNeverSleepsOnlySlowsTheSetDown) {
  FakeProc proc;
  proc.thread(200, 200, 'R');
  BusListeners l(7667, "/opt/semx/bin", 0.1, 0.5, proc.path());
  EXPECT_FALSE(l.caught_up(1.0));
  EXPECT_FALSE(l.caught_up(1.05));
  EXPECT_TRUE(l.caught_up(1.1));  // held 0.1 s: goes on
  EXPECT_EQ(l.gave_up(), 1);
  EXPECT_FALSE(l.caught_up(1.2));  // the next tick waits again
}

TEST(BusListeners, NobodyForeignCostsNothingAndIsNeverWaitedFor) {
  FakeProc proc;
  proc.thread(200, 201, 'R');
  // Port 7668's only reader is a process of the set (busy: its thread runnable).
  BusListeners l(7668, "/usr/bin", 0.1, 0.5, proc.path());
  EXPECT_TRUE(l.caught_up(0.0));
  EXPECT_TRUE(l.foreign().empty());
  EXPECT_TRUE(l.has_room(0.1, 0));
  EXPECT_EQ(l.holds(), 0);
  // A reader that comes later is found at the next scan.
  BusListeners none(7669, "/opt/semx/bin", 0.1, 0.5, proc.path());
  EXPECT_TRUE(none.caught_up(0.0));
  std::ofstream(proc.path() + "/net/udp", std::ios::app) << udp_line(7669, 0, 22);
  EXPECT_TRUE(none.caught_up(0.2));  // before the next scan: not seen yet
  EXPECT_FALSE(none.caught_up(0.6));
  EXPECT_EQ(none.foreign(), std::vector<pid_t>{200});
}

TEST(BusListeners, TheHoldComesFromTheEnvironment) {
  unsetenv("SEMX_FOREIGN_HOLD");
  EXPECT_DOUBLE_EQ(foreign_hold_from_env(), 0.1);
  setenv("SEMX_FOREIGN_HOLD", "0", 1);
  EXPECT_DOUBLE_EQ(foreign_hold_from_env(), 0.0);
  setenv("SEMX_FOREIGN_HOLD", "soon", 1);
  EXPECT_THROW(foreign_hold_from_env(), std::runtime_error);
  unsetenv("SEMX_FOREIGN_HOLD");
  EXPECT_GE(foreign_room_bytes(), 32768u);
}
