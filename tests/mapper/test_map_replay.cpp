// Rebuilding a map from an lcm-logger log (semx-map-replay), on logs written here with
// lcm::LogFile: the map equals the mapper's on the same frames; bad frames are counted; missing,
// foreign, corrupt and truncated logs give clear errors; and the executables' exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>
#include <semx/odometry_t.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "map_messages.hpp"
#include "map_replay.hpp"
#include "mapper_messages.hpp"
#include "mapper_test_util.hpp"
#include "semx/mapper/checkpoint.hpp"

namespace semx::mapper {
namespace {

namespace fs = std::filesystem;

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "semx_replay_" + std::to_string(getpid()) + "_" + name;
}

template <class T>
void write_event(lcm::LogFile& log, const std::string& channel, const T& msg, int64_t timestamp) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  lcm::LogEvent e;
  e.eventnum = 0;
  e.timestamp = timestamp;
  e.channel = channel;
  e.datalen = static_cast<int32_t>(bytes.size());
  e.data = bytes.data();
  ASSERT_EQ(log.writeEvent(&e), 0);
}

struct TestLog {
  std::string path;
  int frames = 0;
  int bad = 0;
};

// A log as lcm-logger would write it while the simulator runs: odometry, depth frames (some
// compressed), plus two depth events that are not frames.
TestLog write_log(const std::string& name, const std::vector<test::RoomFrame>& frames,
                  const runtime::PinholeCamera& cam) {
  TestLog t{temp_file(name), static_cast<int>(frames.size()), 2};
  lcm::LogFile log(t.path, "w");
  EXPECT_TRUE(log.good());
  for (size_t k = 0; k < frames.size(); ++k) {
    const int64_t utime = static_cast<int64_t>(k) * 33333;
    semx::odometry_t odo{};
    odo.utime = utime;
    odo.orientation[0] = 1;
    write_event(log, "ODOMETRY", odo, 1000 + utime);
    write_event(log, "CAMERA_DEPTH",
                depth_message(DepthFrame::view(cam, frames[k].pose, frames[k].depth, utime), k % 2 == 1),
                1000 + utime);
    if (k == 1) {
      // A frame whose pose is NaN, and an odometry message on the depth channel.
      semx::depth_image_t nan_pose =
          depth_message(DepthFrame::view(cam, frames[k].pose, frames[k].depth, utime));
      nan_pose.info.sensor_position[0] = std::numeric_limits<double>::quiet_NaN();
      write_event(log, "CAMERA_DEPTH", nan_pose, 1000 + utime);
      write_event(log, "CAMERA_DEPTH", odo, 1000 + utime);
    }
  }
  return t;
}

// Every frame integrated (the live mapper's integration.frame_period_s = 0).
MapperConfig every_frame() {
  MapperConfig c;
  c.integration.frame_period_s = 0;
  return c;
}

TEST(MapReplay, RebuildsTheMapOfTheLoggedFramesAndWritesItsFiles) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(6, cam, 6);
  const TestLog log = write_log("good.lcmlog", frames, cam);
  MapperConfig cfg = every_frame();
  Mapper replayed(cfg);
  ReplayOptions o;
  o.log_path = log.path;
  const ReplayReport r = replay_log(o, replayed);
  EXPECT_EQ(r.layout.events, 2 * 6 + 2);
  EXPECT_FALSE(r.layout.truncated);
  EXPECT_EQ(r.depth_events, 6 + 2);
  EXPECT_EQ(r.integrated, 6);
  EXPECT_EQ(r.malformed, 2);
  EXPECT_EQ(r.rejected, 0);
  EXPECT_NE(r.first_error.find("not finite"), std::string::npos) << r.first_error;
  EXPECT_EQ(r.channels.at("ODOMETRY"), 6);
  EXPECT_EQ(r.first_utime, 0);
  EXPECT_EQ(r.last_utime, 5 * 33333);

  Mapper live(cfg);
  for (const auto& f : frames) live.integrate(DepthFrame::view(cam, f.pose, f.depth));
  map::VoxelKey diff;
  EXPECT_TRUE(replayed.map().grid().same_states(live.map().grid(), &diff));
  EXPECT_EQ(replayed.seq(), 6);

  const std::string dir = temp_file("out");
  fs::remove_all(dir);
  const auto written = write_map_files(replayed, dir + "/nested", r.last_utime);
  ASSERT_EQ(written.size(), 3u);
  for (const auto& f : written) EXPECT_GT(fs::file_size(f), 0u) << f;
  // The checkpoint is one semx-mapper --checkpoint can start from.
  Mapper restored(cfg);
  restored.load_checkpoint(dir + "/nested/map.ckpt");
  EXPECT_TRUE(restored.map().grid().same_states(live.map().grid()));
  fs::remove_all(dir);
  std::remove(log.path.c_str());
}

// With the default integration.frame_period_s (0.1 s) the replay integrates the frames the live
// node would: of frames 33 ms apart, those at 0 and 99999 us (1 ms of slack), and so the same map.
TEST(MapReplay, SkipsTheFramesTheLiveMapperSkips) {
  const auto cam = test::small_camera();
  const auto frames = test::room_frames(6, cam, 6);
  const TestLog log = write_log("gated.lcmlog", frames, cam);
  Mapper replayed{MapperConfig{}};
  ReplayOptions o;
  o.log_path = log.path;
  const ReplayReport r = replay_log(o, replayed);
  EXPECT_EQ(r.integrated, 2);
  EXPECT_EQ(r.integrated + r.skipped + r.malformed, r.depth_events);
  EXPECT_EQ(r.last_utime, 3 * 33333);
  Mapper live{MapperConfig{}};
  live.integrate(DepthFrame::view(cam, frames[0].pose, frames[0].depth));
  live.integrate(DepthFrame::view(cam, frames[3].pose, frames[3].depth));
  EXPECT_TRUE(replayed.map().grid().same_states(live.map().grid()));
  std::remove(log.path.c_str());
}

TEST(MapReplay, MissingForeignCorruptAndTruncatedLogs) {
  Mapper m{every_frame()};
  ReplayOptions o;
  auto error_of = [&](const std::string& path) -> std::string {
    o.log_path = path;
    try {
      replay_log(o, m);
    } catch (const ReplayError& e) {
      return e.what();
    }
    return "";
  };
  const std::string missing = temp_file("missing.lcmlog");
  EXPECT_NE(error_of(missing).find(missing + ": no such file"), std::string::npos) << error_of(missing);

  const std::string empty = temp_file("empty.lcmlog");
  { std::ofstream f(empty); }
  EXPECT_NE(error_of(empty).find("empty"), std::string::npos);

  const std::string text = temp_file("text.lcmlog");
  {
    std::ofstream f(text);
    f << "resolution: 0.1\nthis is a YAML file, not a log\n";
  }
  EXPECT_NE(error_of(text).find("not an LCM log"), std::string::npos) << error_of(text);

  const auto cam = test::small_camera();
  const TestLog good = write_log("base.lcmlog", test::room_frames(3, cam, 3), cam);
  std::vector<char> bytes;
  {
    std::ifstream f(good.path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(f), {});
  }
  // Corrupt in the middle: the second event's sync word is overwritten.
  const size_t first_event = 28 + 8 + static_cast<size_t>(semx::odometry_t().getEncodedSize());
  {
    std::vector<char> c = bytes;
    c[first_event] = 0;
    const std::string path = temp_file("corrupt.lcmlog");
    std::ofstream(path, std::ios::binary).write(c.data(), static_cast<std::streamsize>(c.size()));
    const std::string e = error_of(path);
    EXPECT_NE(e.find("corrupt"), std::string::npos) << e;
    EXPECT_NE(e.find("byte " + std::to_string(first_event)), std::string::npos) << e;
    EXPECT_NE(e.find("event 1"), std::string::npos) << e;
    std::remove(path.c_str());
  }
  // A header with a negative data length (LCM's own reader would allocate blindly).
  {
    std::vector<char> c = bytes;
    c[first_event + 24] = static_cast<char>(0xFF);
    const std::string path = temp_file("negative.lcmlog");
    std::ofstream(path, std::ios::binary).write(c.data(), static_cast<std::streamsize>(c.size()));
    EXPECT_NE(error_of(path).find("negative data length"), std::string::npos) << error_of(path);
    std::remove(path.c_str());
  }
  // Cut short in the last frame (lcm-logger killed): the complete events are replayed.
  {
    const std::string path = temp_file("truncated.lcmlog");
    std::ofstream(path, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size() - 1000));
    Mapper t{every_frame()};
    o.log_path = path;
    const ReplayReport r = replay_log(o, t);
    EXPECT_TRUE(r.layout.truncated);
    EXPECT_EQ(r.layout.events, 2 * 3 + 2 - 1);
    EXPECT_EQ(r.integrated, 2);
    std::remove(path.c_str());
  }
  std::remove(empty.c_str());
  std::remove(text.c_str());
  std::remove(good.path.c_str());
}

// ---- the executables ----

struct RunResult {
  int code = -1;
  std::string output;
};

RunResult run_program(const std::vector<std::string>& argv) {
  const std::string out = temp_file("run.out");
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* f = std::fopen(out.c_str(), "w");
    if (f) {
      dup2(fileno(f), STDOUT_FILENO);
      dup2(fileno(f), STDERR_FILENO);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  RunResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream f(out);
  r.output.assign(std::istreambuf_iterator<char>(f), {});
  std::remove(out.c_str());
  return r;
}

const std::string kBin = SEMX_BIN_DIR;

TEST(MapReplay, ExecutableWritesTheFilesAndFailsClearly) {
  const auto cam = test::small_camera();
  const TestLog log = write_log("exe.lcmlog", test::room_frames(3, cam, 3), cam);
  const std::string dir = temp_file("exe_out");
  fs::remove_all(dir);
  RunResult r = run_program({kBin + "/semx-map-replay", log.path, "--out", dir, "--set", "resolution=0.2",
                             "--set", "integration.frame_period_s=0"});
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("frames integrated 3, skipped 0 (frame_period_s), rejected 0, malformed 2"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(dir + "/map.ckpt"));
  EXPECT_TRUE(fs::exists(dir + "/map.bt"));
  EXPECT_TRUE(fs::exists(dir + "/map.pcd"));
  EXPECT_EQ(read_checkpoint_info(dir + "/map.ckpt").resolution, 0.2);

  r = run_program({kBin + "/semx-map-replay", dir + "/no_such.lcmlog"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("no_such.lcmlog: no such file"), std::string::npos) << r.output;
  r = run_program({kBin + "/semx-map-replay", dir + "/map.ckpt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("not an LCM log"), std::string::npos) << r.output;
  r = run_program({kBin + "/semx-map-replay", log.path, "--channel", "CAMERA_RGB"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("no CAMERA_RGB events"), std::string::npos) << r.output;
  r = run_program({kBin + "/semx-map-replay"});
  EXPECT_EQ(r.code, 2) << "usage error";

  // semx-mapper refuses a corrupt checkpoint with a message naming it...
  const std::string bad = dir + "/map.ckpt";
  {
    std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('\x55');
  }
  r = run_program({kBin + "/semx-mapper", "--lcm-url", "memq://", "--checkpoint", bad, "--quiet"});
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
  // ... and a config error is a usage-class error (exit 2) naming the key.
  r = run_program({kBin + "/semx-mapper", "--lcm-url", "memq://", "--set", "resolutoin=0.1"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("resolutoin"), std::string::npos) << r.output;
  fs::remove_all(dir);
  std::remove(log.path.c_str());
}

}  // namespace
}  // namespace semx::mapper
