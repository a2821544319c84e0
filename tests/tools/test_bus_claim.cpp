// A set's own port (tools/bus_claim.hpp): two launchers on one host never take one port, a port
// where anything talks counts as busy, and the policy decides what happens then.
#include "semx/tools/bus_claim.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "semx/runtime/udpm_sender.hpp"

namespace fs = std::filesystem;
using semx::tools::BusClaim;
using semx::tools::BusClaimOptions;
using semx::tools::claim_bus;
using semx::tools::PortPolicy;

namespace {

// A port range of this test's own (by pid) and a lock directory of its own, so parallel tests
// and a live set on this machine do not decide the outcome.
struct ClaimTest : ::testing::Test {
  std::string lock_dir;
  int port = 0;
  void SetUp() override {
    lock_dir = (fs::temp_directory_path() / ("semx-claim-test-" + std::to_string(getpid()))).string();
    fs::remove_all(lock_dir);
    port = 21000 + static_cast<int>(getpid() % 4000) * 8;
  }
  void TearDown() override { fs::remove_all(lock_dir); }
  std::string url(int p, int ttl = 0) const {
    return "udpm://239.255.76.67:" + std::to_string(p) + "?ttl=" + std::to_string(ttl);
  }
  BusClaimOptions options(PortPolicy policy) const {
    BusClaimOptions o;
    o.policy = policy;
    o.lock_dir = lock_dir;
    o.listen_s = 0.2;
    return o;
  }
};

void release(BusClaim& c) {
  if (c.lock_fd >= 0) ::close(c.lock_fd);
  c.lock_fd = -1;
}

// Something sending on a port until stopped, as a live set does.
struct Talker {
  std::atomic<bool> stop{false};
  std::thread thread;
  explicit Talker(int port) {
    semx::runtime::UdpmEndpoint e;
    e.group = "239.255.76.67";
    e.port = port;
    e.ttl = 0;
    thread = std::thread([this, e] {
      semx::runtime::UdpmSender sender(e);
      const std::vector<uint8_t> bytes(64, 7);
      while (!stop) {
        sender.publish("NODE_STATUS", bytes.data(), bytes.size());
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
  }
  ~Talker() {
    stop = true;
    thread.join();
  }
};

}  // namespace

TEST_F(ClaimTest, AFreePortIsTakenAndLocked) {
  BusClaim a = claim_bus(url(port), options(PortPolicy::kMove));
  EXPECT_EQ(a.port, port);
  EXPECT_EQ(a.url, url(port));
  EXPECT_TRUE(a.why_moved.empty());
  EXPECT_GE(a.lock_fd, 0);
  release(a);
}

TEST_F(ClaimTest, TwoSetsOnOneHostGetTwoPorts) {
  BusClaim a = claim_bus(url(port), options(PortPolicy::kMove));
  BusClaim b = claim_bus(url(port), options(PortPolicy::kMove));
  EXPECT_EQ(a.port, port);
  EXPECT_EQ(b.port, port + 1);
  EXPECT_EQ(b.url, url(port + 1));
  EXPECT_NE(b.why_moved.find("holds port " + std::to_string(port)), std::string::npos) << b.why_moved;
  // Once the first set ends, its port is free again.
  release(a);
  BusClaim c = claim_bus(url(port), options(PortPolicy::kMove));
  EXPECT_EQ(c.port, port);
  release(b);
  release(c);
}

TEST_F(ClaimTest, RefuseFailsNamingWhyAndShareTakesTheBusyPort) {
  BusClaim a = claim_bus(url(port), options(PortPolicy::kMove));
  try {
    claim_bus(url(port), options(PortPolicy::kRefuse));
    ADD_FAILURE() << "a held port was claimed under refuse";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("holds port " + std::to_string(port)), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--port-policy share"), std::string::npos) << e.what();
  }
  BusClaim s = claim_bus(url(port), options(PortPolicy::kShare));
  EXPECT_EQ(s.port, port);
  EXPECT_FALSE(s.shared.empty());
  release(a);
  release(s);
}

TEST_F(ClaimTest, APortWhereSomethingTalksIsBusy) {
  Talker talker(port + 4);
  BusClaim a = claim_bus(url(port + 4), options(PortPolicy::kMove));
  EXPECT_EQ(a.port, port + 5);
  EXPECT_NE(a.why_moved.find("talks on port " + std::to_string(port + 4)), std::string::npos) << a.why_moved;
  release(a);
}

TEST_F(ClaimTest, AMultiHostUrlNeverMoves) {
  BusClaim a = claim_bus(url(port + 2, 1), options(PortPolicy::kMove));
  EXPECT_EQ(a.port, port + 2);
  EXPECT_THROW(claim_bus(url(port + 2, 1), options(PortPolicy::kMove)), std::runtime_error);
  release(a);
}

TEST_F(ClaimTest, UrlsThatAreNotUdpmPassThrough) {
  BusClaim a = claim_bus("memq://", options(PortPolicy::kRefuse));
  EXPECT_EQ(a.url, "memq://");
  EXPECT_LT(a.lock_fd, 0);
}

TEST(BusClaimUrl, WithPortKeepsTheOptions) {
  EXPECT_EQ(semx::tools::with_port("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304", 7670),
            "udpm://239.255.76.67:7670?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(semx::tools::with_port("udpm://239.255.76.67:7667", 7668), "udpm://239.255.76.67:7668");
}
