// semx-mapper as a real process over udpm on a port of its own: it maps a frame sent over the
// network, survives hostile input on every channel it reads with bounded memory, writes its
// checkpoint on Ctrl-C and restores it on restart.
#include <gtest/gtest.h>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/node_status_t.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "../tools/process_harness.hpp"
#include "map_messages.hpp"
#include "mapper_messages.hpp"
#include "mapper_test_util.hpp"
#include "semx/mapper/checkpoint.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/node.hpp"

namespace semx::mapper {
namespace {

using semx::testing::bin;
using semx::testing::Process;
using semx::testing::test_port;

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "semx_mproc_" + std::to_string(getpid()) + "_" + name;
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

struct Observer {
  runtime::Node node;
  semx::node_status_t status;
  bool seen = false;
  int64_t update_seq = -1;
  int64_t snapshot_seq = -1;

  explicit Observer(const std::string& url) : node(options(url)) {
    node.subscribe<semx::node_status_t>(semx::channels::NODE_STATUS, [this](const semx::node_status_t& s) {
      if (s.node != "mapper") return;
      status = s;
      seen = true;
    });
    node.subscribe<semx::map_update_t>(semx::channels::MAP_UPDATE,
                                       [this](const semx::map_update_t& m) { update_seq = m.seq; });
    node.subscribe<semx::map_snapshot_t>(semx::channels::MAP_SNAPSHOT,
                                         [this](const semx::map_snapshot_t& m) { snapshot_seq = m.seq; });
  }
  static runtime::NodeOptions options(const std::string& url) {
    runtime::NodeOptions o;
    o.name = "observer";
    o.lcm_url = url;
    o.quiet = true;
    o.status_period_s = 1e6;
    return o;
  }
  // Spins until `done` or `seconds` pass; returns done().
  bool until(const std::function<bool()>& done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done() && std::chrono::steady_clock::now() < end) node.spin_once(20);
    return done();
  }
};

TEST(MapperProcess, MapsSurvivesHostileInputAndCheckpointsOnExit) {
  const std::string url = runtime::udpm_url_for_port(test_port(7));
  const std::string checkpoint = temp_file("proc.ckpt");
  std::remove(checkpoint.c_str());
  const std::string log = temp_file("mapper.out");
  Observer obs(url);
  {
    Process mapper({bin("semx-mapper"), "--status-period", "0.2", "--checkpoint", checkpoint, "--quiet"}, log,
                   url);
    ASSERT_TRUE(obs.until([&] { return obs.seen && obs.status.pid == mapper.pid(); }, 5.0))
        << "no NODE_STATUS from the mapper\n"
        << read_file(log);
    const int64_t rss_before = obs.status.rss_kb;

    for (const char* channel : {"CAMERA_DEPTH", "ODOMETRY", "MAP_REQUEST"}) {
      Process hostile(
          {bin("semx-hostile"), "--channel", channel, "--count", "20", "--rate", "2000", "--quiet"},
          temp_file("hostile.out"), url);
      ASSERT_EQ(hostile.wait(20), 0) << channel;
    }
    const auto cam = test::small_camera();
    const auto frames = test::room_frames(1, cam, 1);
    obs.node.publish(semx::channels::CAMERA_DEPTH,
                     depth_message(DepthFrame::view(cam, frames[0].pose, frames[0].depth, 1000), true));
    ASSERT_TRUE(obs.until([&] { return obs.update_seq == 1; }, 5.0)) << "no MAP_UPDATE\n" << read_file(log);
    obs.node.publish(semx::channels::MAP_REQUEST, map::request_message("observer", -1, 0));
    ASSERT_TRUE(obs.until([&] { return obs.snapshot_seq == 1; }, 5.0)) << "no MAP_SNAPSHOT";
    // A fresh status after all of it.
    obs.seen = false;
    ASSERT_TRUE(obs.until([&] { return obs.seen; }, 5.0));

    EXPECT_TRUE(mapper.alive());
    // Every one of the 7 kinds x 20 on CAMERA_DEPTH is dropped (a bit flip that leaves valid
    // bytes still fails the frame checks); on ODOMETRY and MAP_REQUEST some bit flips are valid.
    int64_t depth_malformed = -1;
    for (const auto& c : obs.status.channels) {
      if (c.channel == "CAMERA_DEPTH" && !c.outgoing) depth_malformed = c.malformed;
    }
    EXPECT_EQ(depth_malformed, 7 * 20);
    EXPECT_GE(obs.status.malformed, 7 * 20 + 2 * 5 * 20);
    EXPECT_EQ(obs.status.handler_errors, 0);
    EXPECT_LT(obs.status.rss_kb - rss_before, 40 * 1024) << "memory grew under hostile input";

    mapper.signal(SIGINT);
    EXPECT_EQ(mapper.wait(5), 0) << read_file(log);
  }
  ASSERT_TRUE(std::filesystem::exists(checkpoint)) << "no checkpoint written on exit\n" << read_file(log);
  EXPECT_EQ(read_checkpoint_info(checkpoint).seq, 1);
  EXPECT_NE(read_file(log).find("1 frames integrated"), std::string::npos) << read_file(log);

  // Restarted, it continues from the checkpoint: the next delta's seq jumps (clients resync).
  {
    Process mapper({bin("semx-mapper"), "--checkpoint", checkpoint, "--quiet"}, log, url);
    const auto cam = test::small_camera();
    const auto frames = test::room_frames(2, cam, 2);
    // (A status of the new process: the old one's last may still be queued here.)
    ASSERT_TRUE(obs.until([&] { return obs.seen && obs.status.pid == mapper.pid(); }, 5.0));
    obs.node.publish(semx::channels::CAMERA_DEPTH,
                     depth_message(DepthFrame::view(cam, frames[1].pose, frames[1].depth, 2000)));
    ASSERT_TRUE(obs.until([&] { return obs.update_seq == 2 + Mapper::kRestoreSequenceJump; }, 5.0))
        << "seq " << obs.update_seq << "\n"
        << read_file(log);
    mapper.signal(SIGINT);
    EXPECT_EQ(mapper.wait(5), 0);
  }
  EXPECT_NE(read_file(log).find("restored"), std::string::npos) << read_file(log);
  std::remove(checkpoint.c_str());
  std::remove(log.c_str());
}

}  // namespace
}  // namespace semx::mapper
