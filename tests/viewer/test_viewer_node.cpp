// The viewer node over memq://, from a file:// log and as a process: frames on message time
// (with and without a clock, in lockstep), hostile messages survived, and a log played into it
// giving the same pictures as the live run.
#include <gtest/gtest.h>
#include <unistd.h>

#include <semx/clock_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/trajectory_t.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <sstream>

#include "map_messages.hpp"
#include "semx/runtime/channels.hpp"
#include "viewer_node.hpp"

namespace semx::viewer {
namespace {

namespace fs = std::filesystem;
namespace ch = semx::channels;

struct Event {
  std::string channel;
  std::vector<uint8_t> bytes;
};

template <class T>
Event event(const char* channel, const T& m) {
  Event e{channel, std::vector<uint8_t>(static_cast<size_t>(m.getEncodedSize()))};
  m.encode(e.bytes.data(), 0, static_cast<int>(e.bytes.size()));
  return e;
}

semx::odometry_t odometry(int64_t t, double x, double y) {
  semx::odometry_t o{};
  o.utime = t;
  o.position[0] = x;
  o.position[1] = y;
  o.position[2] = 1;
  o.orientation[0] = 1;
  return o;
}

semx::roadmap_t roadmap(int64_t t, int n) {
  semx::roadmap_t r{};
  r.utime = t;
  r.iteration = 1;
  for (int i = 0; i < n; ++i) {
    semx::roadmap_node_t x{};
    x.id = i;
    x.position[0] = 0.5 + 0.5 * i;
    x.position[1] = 2;
    x.position[2] = 1;
    x.score = i;
    x.flags = i == n - 1 ? semx::roadmap_node_t::GOAL : 0;
    r.nodes.push_back(x);
    if (i > 0) {
      r.edge_from.push_back(i - 1);
      r.edge_to.push_back(i);
    }
  }
  r.num_nodes = static_cast<int32_t>(r.nodes.size());
  r.num_edges = static_cast<int32_t>(r.edge_from.size());
  return r;
}

semx::semantic_regions_t regions(int64_t t) {
  semx::semantic_regions_t m{};
  m.utime = t;
  m.seq = 1;
  semx::semantic_region_t r{};
  r.id = 1;
  r.class_id = 5;
  r.label = "chair";
  r.centroid[0] = 2.5;
  r.centroid[1] = 0.5;
  r.centroid[2] = 0.4;
  r.weight = 1;
  r.radius = 0.7;
  r.active = true;
  m.regions.push_back(r);
  m.num_regions = 1;
  return m;
}

semx::path_t path(int64_t t) {
  semx::path_t p{};
  p.utime = t;
  p.plan_id = 1;
  p.waypoints = {{1.5, 1, 1}, {2.5, 1.5, 1}, {3.5, 2, 1}};
  p.yaws = {0, 0, 0};
  p.num_waypoints = 3;
  return p;
}

semx::planner_status_t status(int64_t t, int8_t state) {
  semx::planner_status_t s{};
  s.utime = t;
  s.planner = "test-planner";
  s.state = state;
  s.reason = "";
  return s;
}

// A 3 s run at 10 Hz: odometry, then the clock (optional), then what the nodes publish for the
// tick: a map delta every 0.2 s revealing free space along the flight, the roadmap and path at
// 1.0 s, regions at 1.5 s, planner status every 0.5 s.
std::vector<Event> scene(bool clock, int ticks = 31) {
  std::vector<Event> out;
  int64_t seq = 0;
  for (int k = 0; k < ticks; ++k) {
    const int64_t t = k * 100000;
    const double x = 0.5 + 1e-6 * t;
    out.push_back(event(ch::ODOMETRY, odometry(t, x, 1)));
    if (clock) {
      semx::clock_t c{};
      c.utime = t;
      c.tick = k;
      c.mode = semx::clock_t::LOCKSTEP;
      c.period_us = 100000;
      out.push_back(event(ch::SIM_CLOCK, c));
    }
    if (k % 2 == 0) {
      map::MapDelta d;
      d.seq = ++seq;
      d.utime = t;
      d.resolution = 0.1;
      const int kx = static_cast<int>(std::floor(x / 0.1));
      for (int ix = kx - 3; ix <= kx + 3; ++ix) {
        for (int iy = 5; iy <= 15; ++iy) d.changes.push_back({{ix, iy, 10}, map::VoxelState::kFree});
      }
      d.changes.push_back({{kx, 17, 10}, map::VoxelState::kOccupied});
      out.push_back(event(ch::MAP_UPDATE, map::to_message(d)));
    }
    if (t == 1000000) {
      out.push_back(event(ch::ROADMAP, roadmap(t, 5)));
      out.push_back(event(ch::PLAN_PATH, path(t)));
    }
    if (t == 1500000) out.push_back(event(ch::SEMANTIC_REGIONS, regions(t)));
    if (k % 5 == 0) out.push_back(event(ch::PLANNER_STATUS, status(t, semx::planner_status_t::EXECUTING)));
  }
  return out;
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "semx_viewer_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(d);
  return d;
}

runtime::NodeOptions node_options(const std::string& url = "memq://", bool lockstep = false) {
  runtime::NodeOptions no;
  no.name = "viewer";
  no.lcm_url = url;
  no.quiet = true;
  no.status_period_s = 1e6;
  no.lockstep = lockstep;
  return no;
}

std::vector<std::string> pngs(const std::string& dir) {
  std::vector<std::string> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

struct FrameState {
  size_t nodes = 0;
  size_t regions = 0;
  size_t trail = 0;
  int64_t map_seq = 0;
  int64_t time = 0;
};

struct Live {
  std::map<int64_t, FrameState> frames;
  runtime::NodeCounters counters;
  int64_t acks = 0;
  std::string dir;
};

Live run_live(const std::string& name, const std::vector<Event>& events, bool lockstep,
              std::vector<Event> after = {}) {
  Live live;
  live.dir = temp_dir(name);
  runtime::Node node(node_options("memq://", lockstep));
  ViewerNodeOptions o;
  o.out_dir = live.dir;
  o.period_s = 0.5;
  o.print = false;
  ViewerNode* self = nullptr;
  o.on_frame = [&](const evaluator::Image& img, int64_t index) {
    EXPECT_GT(img.width, 0);
    live.frames[index] = {self->view().roadmap().nodes.size(), self->view().regions().size(),
                          self->view().trail().size(), self->map().seq(), self->view().time_utime()};
  };
  ViewerNode v(node, o);
  self = &v;
  for (const auto& e : events) {
    node.publish_raw(e.channel, e.bytes.data(), e.bytes.size());
    node.drain();
  }
  for (const auto& e : after) {
    node.publish_raw(e.channel, e.bytes.data(), e.bytes.size());
    node.drain();
  }
  v.draw_frame(-1);
  live.counters = node.counters();
  const auto it = node.outgoing().find(ch::SIM_ACK);
  live.acks = it == node.outgoing().end() ? 0 : it->second.messages;
  return live;
}

void write_log(const std::string& path, const std::vector<Event>& events) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  int64_t n = 0;
  for (const auto& e : events) {
    lcm::LogEvent le;
    le.eventnum = n;
    le.timestamp = 1700000000000000 + 1000 * n++;
    le.channel = e.channel;
    le.datalen = static_cast<int32_t>(e.bytes.size());
    le.data = const_cast<uint8_t*>(e.bytes.data());
    ASSERT_EQ(log.writeEvent(&le), 0);
  }
}

TEST(ViewerNode, WritesAFramePerPeriodOfMessageTimeWithoutAClock) {
  const Live live = run_live("noclock", scene(false), false);
  std::vector<std::string> expected;
  for (int k = 0; k <= 6; ++k) expected.push_back(frame_file_name(k));
  expected.push_back("final.png");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(pngs(live.dir), expected);
  for (const auto& f : expected) EXPECT_GT(fs::file_size(live.dir + "/" + f), 1000u) << f;
  // Frame k shows what was stamped before k * 0.5 s: the roadmap (1.0 s) from frame 3 on, the
  // regions (1.5 s) from frame 4 on.
  ASSERT_EQ(live.frames.size(), 8u);
  EXPECT_EQ(live.frames.at(2).nodes, 0u);
  EXPECT_EQ(live.frames.at(3).nodes, 5u);
  EXPECT_EQ(live.frames.at(3).regions, 0u);
  EXPECT_EQ(live.frames.at(4).regions, 1u);
  EXPECT_EQ(live.frames.at(0).map_seq, 0);
  EXPECT_EQ(live.frames.at(1).map_seq, 3);  // deltas at 0, 0.2, 0.4 s
  EXPECT_EQ(live.frames.at(6).map_seq, 15);
  EXPECT_EQ(live.frames.at(-1).map_seq, 16);
  EXPECT_GT(live.frames.at(6).trail, live.frames.at(1).trail);
  EXPECT_EQ(live.counters.malformed, 0);
  EXPECT_EQ(live.counters.handler_errors, 0);
  // The pictures change as the run goes on.
  EXPECT_NE(slurp(live.dir + "/frame_000001.png"), slurp(live.dir + "/frame_000006.png"));
}

TEST(ViewerNode, InLockstepDrawsOnTicksAndAcksThem) {
  semx::clock_t restart{};
  restart.utime = 0;
  restart.tick = 0;
  restart.mode = semx::clock_t::LOCKSTEP;
  restart.period_us = 100000;
  const Live live = run_live("lockstep", scene(true), true, {event(ch::SIM_CLOCK, restart)});
  EXPECT_EQ(live.acks, 32);  // 31 ticks and the new episode's tick 0
  for (int k = 0; k <= 6; ++k) EXPECT_TRUE(fs::is_regular_file(live.dir + "/" + frame_file_name(k))) << k;
  EXPECT_EQ(live.frames.at(2).nodes, 0u);  // the roadmap comes after the 1.0 s tick
  EXPECT_EQ(live.frames.at(3).nodes, 5u);
  // The map client applies a tick's deltas at the next tick: frame 1 (tick 5) has 0, 0.2, 0.4 s.
  EXPECT_EQ(live.frames.at(1).map_seq, 3);
  EXPECT_EQ(live.frames.at(6).time, 3000000);
  // The new episode redrew frame 0 without the old trail (the map stays).
  EXPECT_EQ(live.frames.at(0).trail, 0u);
  EXPECT_EQ(live.frames.at(0).nodes, 0u);
  EXPECT_GE(live.frames.at(0).map_seq, 15);
}

TEST(ViewerNode, SurvivesHostileMessagesAndKeepsDrawing) {
  std::vector<Event> bad;
  const std::vector<uint8_t> junk = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17};
  for (const char* c : {ch::ROADMAP, ch::SEMANTIC_REGIONS, ch::PLAN_PATH, ch::TRAJECTORY, ch::ODOMETRY,
                        ch::PLANNER_STATUS, ch::MAP_UPDATE, ch::MAP_SNAPSHOT, ch::SIM_CLOCK}) {
    bad.push_back({c, junk});
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bad.push_back(event(ch::ODOMETRY, odometry(500000, nan, 1)));
  bad.push_back(event(ch::ODOMETRY, odometry(600000, 1e300, -1e300)));
  bad.push_back(event(ch::ODOMETRY, odometry(std::numeric_limits<int64_t>::max() / 2, 1, 1)));  // far future
  semx::roadmap_t big = roadmap(700000, 20000);
  for (int i = 0; i < 20000; i += 7) big.nodes[i].position[1] = nan;
  big.nodes[1].score = std::numeric_limits<double>::infinity();
  big.edge_from.push_back(-5);
  big.edge_to.push_back(123456789);
  big.num_edges = static_cast<int32_t>(big.edge_from.size());
  bad.push_back(event(ch::ROADMAP, big));
  semx::semantic_regions_t r = regions(800000);
  r.regions[0].radius = nan;
  r.regions.push_back(regions(800000).regions[0]);
  r.regions.back().radius = 1e200;
  r.regions.back().label = std::string(5000, '\x01');
  r.num_regions = 2;
  bad.push_back(event(ch::SEMANTIC_REGIONS, r));
  semx::path_t p = path(900000);
  p.waypoints[1][0] = nan;
  bad.push_back(event(ch::PLAN_PATH, p));
  semx::trajectory_t tr{};
  tr.utime = 900000;
  tr.degree = 3;
  tr.knot_interval = -1e300;
  tr.num_control_points = 5;
  tr.control_points.assign(5, {nan, 1e300, 0});
  tr.yaw_control_points.assign(5, nan);
  bad.push_back(event(ch::TRAJECTORY, tr));
  semx::planner_status_t s = status(900000, 99);
  s.planner = std::string(10000, 'p');
  bad.push_back(event(ch::PLANNER_STATUS, s));
  // The normal run goes on around them.
  std::vector<Event> events;
  const auto normal = scene(false);
  events.insert(events.end(), normal.begin(), normal.begin() + 16);
  events.insert(events.end(), bad.begin(), bad.end());
  events.insert(events.end(), normal.begin() + 16, normal.end());
  const Live live = run_live("hostile", events, false);
  EXPECT_EQ(live.counters.handler_errors, 0);
  EXPECT_GE(live.counters.malformed, 9);
  // The far-future stamp did not stop the frames; all of them were still written.
  for (int k = 0; k <= 6; ++k) EXPECT_TRUE(fs::is_regular_file(live.dir + "/" + frame_file_name(k))) << k;
  EXPECT_LE(live.frames.at(6).time, 3000000);
  EXPECT_EQ(live.frames.at(6).nodes, 5u);  // the good roadmap at 1.0 s came after the huge one
  EXPECT_TRUE(fs::is_regular_file(live.dir + "/final.png"));
}

TEST(ViewerNode, ALogPlayedIntoItGivesTheLiveRunsPictures) {
  const auto events = scene(true);
  const Live live = run_live("live", events, false);
  const std::string dir = temp_dir("replay");
  fs::create_directories(dir);
  const std::string log = dir + "/run.lcmlog";
  write_log(log, events);
  const std::string out = dir + "/frames";
  {
    runtime::Node node(node_options("file://" + log + "?speed=0"));
    ViewerNodeOptions o;
    o.out_dir = out;
    o.period_s = 0.5;
    o.print = false;
    ViewerNode v(node, o);
    EXPECT_EQ(v.run(), 0);  // returns at the end of the log
    EXPECT_EQ(v.frames_drawn(), 8);
  }
  const auto a = pngs(live.dir), b = pngs(out);
  ASSERT_EQ(a.size(), 8u);
  ASSERT_EQ(a, b);
  for (const auto& f : a) EXPECT_EQ(slurp(live.dir + "/" + f), slurp(out + "/" + f)) << f;
}

TEST(ViewerNode, AFolderThatCannotBeMadeIsAnErrorAtStart) {
  const std::string dir = temp_dir("file");
  fs::create_directories(dir);
  std::ofstream(dir + "/x") << "a file";
  runtime::Node node(node_options());
  ViewerNodeOptions o;
  o.out_dir = dir + "/x/frames";
  EXPECT_THROW(ViewerNode(node, o), std::runtime_error);
}

#ifdef SEMX_BIN_DIR
int run(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(SemxViewer, ReplaysALogIntoFramesAndFallsBackWithoutADisplay) {
  const std::string dir = temp_dir("exe");
  fs::create_directories(dir);
  write_log(dir + "/run.lcmlog", scene(true));
  const std::string cmd = "env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SEMX_BIN_DIR) +
                          "/semx-viewer --quiet --window --period 1 --scale 40 --lcm-url 'file://" + dir +
                          "/run.lcmlog?speed=0' --out " + dir + "/frames > " + dir + "/out.txt 2> " + dir +
                          "/err.txt";
  EXPECT_EQ(run(cmd), 0) << slurp(dir + "/err.txt");
  EXPECT_NE(slurp(dir + "/err.txt").find("no window"), std::string::npos) << slurp(dir + "/err.txt");
  const auto f = pngs(dir + "/frames");
  EXPECT_EQ(f, (std::vector<std::string>{"final.png", "frame_000000.png", "frame_000001.png",
                                         "frame_000002.png", "frame_000003.png"}));
  EXPECT_EQ(run(std::string(SEMX_BIN_DIR) + "/semx-viewer --period -1 > /dev/null 2>&1"), 2);
  EXPECT_EQ(run(std::string(SEMX_BIN_DIR) + "/semx-viewer --area 1,2,3 > /dev/null 2>&1"), 2);
  EXPECT_EQ(run(std::string(SEMX_BIN_DIR) + "/semx-viewer --world /nonexistent.yaml > /dev/null 2>&1"), 2);
}
#endif

}  // namespace
}  // namespace semx::viewer
