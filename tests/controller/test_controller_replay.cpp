// Generating a logged run's paths again (controller_replay.hpp), on logs written here with
// lcm::LogFile: each path meets the ESDF and odometry logged before it and the configuration
// given; paths without them, outside the window or malformed are counted, not generated; a
// missing log is an error naming it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "controller_replay.hpp"
#include "fields.hpp"
#include "node_messages.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::controller {
namespace {

namespace ch = semx::channels;
using test::esdf_message;
using test::odometry;
using test::path_message;

template <class T>
void write_event(lcm::LogFile& log, const std::string& channel, const T& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  lcm::LogEvent e;
  e.eventnum = 0;
  e.timestamp = 0;
  e.channel = channel;
  e.datalen = static_cast<int32_t>(bytes.size());
  e.data = bytes.data();
  ASSERT_EQ(log.writeEvent(&e), 0);
}

// A doorway whose jambs' ends are 0.72 m apart and 0.15 m apart along the way: the camera 35° off
// the direction of travel needs its heading held through it (test_body_heading.cpp).
GridDistanceField doorway() {
  const Eigen::Vector2d a(2.0, 0.36), b(2.15, -0.36);
  return test::sample_grid(
      [&](const Eigen::Vector3d& p) { return std::min((p.head<2>() - a).norm(), (p.head<2>() - b).norm()); },
      Eigen::Vector3d(-1.0, -2.0, 0.0), 0.05, 120, 80, 40);
}

std::string write_log(const std::string& name) {
  const std::string path = ::testing::TempDir() + "semx_ctl_replay_" + std::to_string(getpid()) + "_" + name;
  lcm::LogFile log(path, "w");
  EXPECT_TRUE(log.good());
  const double yaw = 35.0 * M_PI / 180;
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 1}, {1.2, 0, 1}, {2.8, 0, 1}, {4, 0, 1}};
  semx::odometry_t odo = odometry(pts[0], 1'000'000);
  odo.orientation[0] = std::cos(yaw / 2);
  odo.orientation[3] = std::sin(yaw / 2);
  write_event(log, ch::PLAN_PATH, path_message(pts, 1, 1'000'000, yaw));  // no map, no vehicle yet
  write_event(log, ch::ODOMETRY, odo);
  write_event(log, ch::ESDF_LOCAL, esdf_message(doorway(), 1'000'000));
  write_event(log, ch::PLAN_PATH, path_message(pts, 2, 2'000'000, yaw));
  write_event(log, ch::PLAN_PATH, odo);  // not a path
  std::vector<Eigen::Vector3d> far = pts;
  far[0] = Eigen::Vector3d(0, 3, 1);  // 3 m from the vehicle: the controller rejects it
  write_event(log, ch::PLAN_PATH, path_message(far, 3, 3'000'000, yaw));
  write_event(log, ch::PLAN_PATH, path_message(pts, 4, 9'000'000, yaw));
  return path;
}

TEST(ControllerReplay, EachPathMeetsTheMapAndVehicleLoggedBeforeItAndTheGivenConfiguration) {
  const std::string log = write_log("doorway.lcmlog");
  ControllerConfig config;
  const PathReplay r = replay_paths(log, config);
  EXPECT_EQ(r.esdf_events, 1);
  EXPECT_EQ(r.malformed, 1);
  EXPECT_EQ(r.skipped, 2);  // path 1 (no map yet), path 3 (its start far from the vehicle)
  ASSERT_EQ(r.paths.size(), 2u);
  EXPECT_EQ(r.paths[0].plan_id, 2);
  EXPECT_DOUBLE_EQ(r.paths[0].time, 2.0);
  EXPECT_EQ(r.paths[0].waypoints, 4u);
  const GenerationResult& held = r.paths[0].generation;
  ASSERT_TRUE(held.ok) << held.reason;
  EXPECT_TRUE(held.trajectory.optimized) << held.reason;
  EXPECT_FALSE(held.slowed) << held.reason;
  EXPECT_GE(held.repaired_headings, 1);

  // Without the heading repairs the same path is flown on the fallback, and says why.
  config.clearance.heading_repairs = 0;
  const PathReplay off = replay_paths(log, config, 1.5, 5.0);
  ASSERT_EQ(off.paths.size(), 1u) << "path 4 (9 s) is outside [1.5, 5)";
  const GenerationResult& plain = off.paths[0].generation;
  ASSERT_TRUE(plain.ok) << plain.reason;
  EXPECT_FALSE(plain.trajectory.optimized);
  EXPECT_NE(plain.reason.find("turned body"), std::string::npos) << plain.reason;
  EXPECT_GT(plain.trajectory.duration(), held.trajectory.duration());
  std::remove(log.c_str());
}

TEST(ControllerReplay, AMissingLogIsAnErrorNamingIt) {
  const std::string missing = ::testing::TempDir() + "semx_no_such_log.lcmlog";
  try {
    replay_paths(missing, ControllerConfig());
    FAIL() << "no error";
  } catch (const ReplayError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace semx::controller
