// semx-ros-bridge as a process between a real roscore and a udpm LCM group: every topic appears
// with its type, frame and content; the LCM side goes on while the master is gone and the bridge
// registers again with a new master; external mode turns ROS sensors into semx's messages and
// semx's commands into MAVROS setpoints. Each test runs its own roscore on a private port.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sys/socket.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <semx/camera_info_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/control_cmd_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/trajectory_t.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>

#include "../tools/process_harness.hpp"
#include "ros_messages.hpp"
#include "map_messages.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/ros/cloud_conversion.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/status_conversion.hpp"
#include "semx/runtime/camera_info.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/node.hpp"

using namespace semx;
using namespace semx::testing;
using semx::rosbridge::from_ros_msg;

namespace {

// The master's TCP port, chosen once per process. Below the kernel's ephemeral range (32768 up):
// test_port's range reaches into it, and a client socket that happens to hold the port makes
// roscore exit with "port ... is already in use" (one way for a roscore never to answer, as one
// did in a CI run whose log was lost). A candidate that cannot be bound now is skipped, as
// roscore's own bind would fail on it.
bool tcp_port_free(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return false;
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // as roscore's server does
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = htons(static_cast<uint16_t>(port));
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}
int ros_port() {
  static const int port = [] {
    const int base = 12000 + (static_cast<int>(getpid()) % 1500) * 10;
    for (int k = 1; k < 10; ++k)
      if (tcp_port_free(base + k)) return base + k;
    return base + 1;  // roscore's log then says why it did not start
  }();
  return port;
}
std::string lcm_url() { return runtime::udpm_url_for_port(test_port(0)); }
std::string log_dir() {
  const std::string d = ::testing::TempDir() + "/semx_ros_live_" + std::to_string(getpid());
  std::filesystem::create_directories(d);
  return d;
}

// One ROS node per test process, on the process's master port (every test starts its own
// roscore there).
void init_ros() {
  static bool done = false;
  if (done) return;
  done = true;
  setenv("ROS_MASTER_URI", ("http://localhost:" + std::to_string(ros_port())).c_str(), 1);
  setenv("ROS_HOME", log_dir().c_str(), 1);
  ::ros::M_string remap;
  ::ros::init(remap, "semx_bridge_test", ::ros::init_options::AnonymousName | ::ros::init_options::NoSigintHandler |
                                             ::ros::init_options::NoRosout);
}

class RosCore {
 public:
  RosCore() {
    init_ros();
    core_ = std::make_unique<Process>(std::vector<std::string>{"/usr/bin/roscore", "-p", std::to_string(ros_port())},
                                      log_dir() + "/roscore.log");
    for (int i = 0; i < 300 && !::ros::master::check(); ++i) ::usleep(100000);
    up_ = ::ros::master::check();
  }
  ~RosCore() { stop(); }
  bool up() const { return up_; }
  // For a failed start: the port and the end of roscore's log.
  std::string why() const {
    std::ifstream f(log_dir() + "/roscore.log");
    const std::string log((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return "roscore on port " + std::to_string(ros_port()) + " did not answer; its log ends:\n" +
           log.substr(log.size() > 1500 ? log.size() - 1500 : 0);
  }
  // roslaunch stops the master and rosout on SIGINT; then nothing answers on the port.
  void stop() {
    if (!core_) return;
    core_->signal(SIGINT);
    core_->wait(15);
    core_.reset();
    for (int i = 0; i < 100 && ::ros::master::check(); ++i) ::usleep(100000);
  }

 private:
  std::unique_ptr<Process> core_;
  bool up_ = false;
};

std::unique_ptr<Process> start_bridge(const std::string& name, std::vector<std::string> extra = {}) {
  std::vector<std::string> argv{bin("semx-ros-bridge"), "--lcm-url", lcm_url(), "--set", "master_check_s=0.2"};
  for (auto& e : extra) argv.push_back(e);
  return std::make_unique<Process>(argv, log_dir() + "/" + name + ".log");
}

runtime::Node make_lcm_node(const std::string& name) {
  runtime::NodeOptions o;
  o.name = name;
  o.lcm_url = lcm_url();
  o.follow_clock = false;
  o.quiet = true;
  return runtime::Node(o);
}

// Spins the test's ROS queue and LCM node until `done` or the timeout.
bool spin_until(::ros::CallbackQueue& q, runtime::Node* lcm, double timeout_s, const std::function<bool()>& done,
                const std::function<void()>& each = nullptr) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (each) each();
    q.callAvailable(::ros::WallDuration(0.01));
    if (lcm) lcm->drain();
    if (done()) return true;
  }
  return false;
}

// A synthetic semx set: what the simulator, mapper, planner and controller would send.
struct FakeSet {
  runtime::Node node = make_lcm_node("fake_set");
  int64_t tick = 0;
  std::vector<map::VoxelKey> occupied{{10, 5, 8}, {11, 5, 8}, {-3, 20, 9}};
  Eigen::Vector3d position{1.0, 2.0, 1.2};

  semx::odometry_t odometry(int64_t utime) const {
    semx::odometry_t m{};
    m.utime = utime;
    m.position[0] = position.x();
    m.position[1] = position.y();
    m.position[2] = position.z();
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
    m.orientation[0] = q.w();
    m.orientation[1] = q.x();
    m.orientation[2] = q.y();
    m.orientation[3] = q.z();
    m.velocity[0] = 0.3;
    return m;
  }
  runtime::PinholeCamera camera() const {
    runtime::PinholeCamera c;
    c.width = 16;
    c.height = 12;
    c.fx = c.fy = 8;
    c.cx = 8;
    c.cy = 6;
    return c;
  }
  Eigen::Isometry3d camera_pose() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix() * runtime::optical_in_body();
    T.translation() = position;
    return T;
  }
  std::vector<uint16_t> depth() const {
    std::vector<uint16_t> d(16 * 12);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = static_cast<uint16_t>(800 + 10 * i);
    return d;
  }

  // One 10 ms tick with its sensors; the slower messages every 50 ticks.
  void step() {
    const int64_t utime = tick * 10000;
    node.publish(channels::ODOMETRY, odometry(utime));
    if (tick % 10 == 0) {
      const auto d = depth();
      node.publish(channels::CAMERA_DEPTH,
                   runtime::depth_image_message(camera(), camera_pose(), d.data(), d.size(), utime, tick / 10,
                                                runtime::ImageCompression::kNone));
      semx::label_image_t l{};
      l.utime = utime;
      l.info = runtime::to_camera_info(camera(), camera_pose(), tick / 10);
      l.label_compression = 0;
      l.label_data.assign(4 * 16 * 12, 0);
      l.label_data[0] = 5;  // a chair pixel, instance 0
      l.num_label_bytes = static_cast<int32_t>(l.label_data.size());
      node.publish(channels::CAMERA_LABELS, l);
    }
    if (tick % 50 == 0) {
      // The map as a snapshot, again and again, as the mapper answers a MAP_REQUEST: a bridge
      // that subscribed after the first one still gets it.
      map::StateGrid grid(0.1);
      for (const auto& k : occupied) grid.set_state(k, map::VoxelState::kOccupied);
      node.publish(channels::MAP_SNAPSHOT, map::to_message(map::encode_snapshot(grid, 1, utime)));
      semx::esdf_local_t e{};
      e.utime = utime;
      e.resolution = 0.1;
      e.origin[0] = 0.0;
      e.origin[1] = 1.0;
      e.origin[2] = 1.0;
      e.nx = 4;
      e.ny = 3;
      e.nz = 3;
      e.max_distance = 2.0;
      e.num_cells = 36;
      for (int i = 0; i < 36; ++i) e.distance.push_back(0.05f * i);
      node.publish(channels::ESDF_LOCAL, e);
      semx::roadmap_t r{};
      r.utime = utime;
      for (int i = 0; i < 3; ++i) {
        semx::roadmap_node_t n{};
        n.id = i;
        n.position[0] = i;
        n.position[2] = 1.0;
        n.score = i;
        r.nodes.push_back(n);
      }
      r.num_nodes = 3;
      r.edge_from = {0, 1};
      r.edge_to = {1, 2};
      r.num_edges = 2;
      node.publish(channels::ROADMAP, r);
      semx::semantic_regions_t g{};
      g.utime = utime;
      semx::semantic_region_t reg{};
      reg.id = 3;
      reg.class_id = 5;
      reg.label = "chair";
      reg.centroid[0] = 2.0;
      reg.radius = 0.5;
      reg.active = true;
      g.regions.push_back(reg);
      g.num_regions = 1;
      node.publish(channels::SEMANTIC_REGIONS, g);
      semx::path_t p{};
      p.utime = utime;
      p.plan_id = 1;
      p.waypoints = {{1.0, 2.0, 1.2}, {2.0, 2.5, 1.2}};
      p.yaws = {0.7, 0.2};
      p.num_waypoints = 2;
      node.publish(channels::PLAN_PATH, p);
      semx::trajectory_t t{};
      t.utime = utime;
      t.plan_id = 1;
      t.start_utime = utime;
      t.degree = 3;
      t.knot_interval = 0.25;
      for (int i = 0; i < 6; ++i) {
        t.control_points.push_back({1.0 + 0.2 * i, 2.0, 1.2});
        t.yaw_control_points.push_back(0.7);
      }
      t.num_control_points = 6;
      node.publish(channels::TRAJECTORY, t);
      semx::planner_status_t s{};
      s.utime = utime;
      s.planner = "semantic-dep";
      s.state = semx::planner_status_t::EXECUTING;
      s.reason = "goal 7";
      s.iteration = tick / 50;
      s.goal[0] = 2.0;
      node.publish(channels::PLANNER_STATUS, s);
    }
    semx::clock_t c{};
    c.utime = utime;
    c.tick = tick;
    c.mode = semx::clock_t::REALTIME;
    c.speed = 1.0;
    c.period_us = 10000;
    node.publish(channels::SIM_CLOCK, c);
    ++tick;
    ::usleep(1000);  // a few hundred ticks a second: faster than real time, not a flood
  }
};

// The last message of each topic, by type.
struct Listener {
  ::ros::CallbackQueue queue;
  std::unique_ptr<::ros::NodeHandle> nh;
  std::vector<::ros::Subscriber> subs;
  std::map<std::string, int> count;
  nav_msgs::Odometry odom;
  std::map<std::string, sensor_msgs::Image> images;
  std::map<std::string, sensor_msgs::CameraInfo> infos;
  std::map<std::string, sensor_msgs::PointCloud2> clouds;
  std::map<std::string, visualization_msgs::MarkerArray> markers;
  std::map<std::string, nav_msgs::Path> paths;
  diagnostic_msgs::DiagnosticArray status;
  std::map<std::string, geometry_msgs::TransformStamped> tf;  // by "parent>child"
  ::ros::Time clock;

  void subscribe() {
    subs.clear();
    nh = std::make_unique<::ros::NodeHandle>();
    nh->setCallbackQueue(&queue);
    auto add = [&](const std::string& topic, auto* target_map_or_value) {
      using Ptr = std::remove_pointer_t<decltype(target_map_or_value)>;
      if constexpr (std::is_same_v<Ptr, nav_msgs::Odometry> || std::is_same_v<Ptr, diagnostic_msgs::DiagnosticArray>) {
        subs.push_back(nh->subscribe<Ptr>(topic, 10, [this, topic, target_map_or_value](const typename Ptr::ConstPtr& m) {
          *target_map_or_value = *m;
          ++count[topic];
        }));
      } else {
        using M = typename Ptr::mapped_type;
        subs.push_back(nh->subscribe<M>(topic, 10, [this, topic, target_map_or_value](const typename M::ConstPtr& m) {
          (*target_map_or_value)[topic] = *m;
          ++count[topic];
        }));
      }
    };
    add("/semx/odom", &odom);
    add("/semx/camera/depth/image_raw", &images);
    add("/semx/camera/labels/image_raw", &images);
    add("/semx/camera/depth/camera_info", &infos);
    add("/semx/map", &clouds);
    add("/semx/map_free", &clouds);
    add("/semx/esdf_slice", &clouds);
    add("/semx/roadmap", &markers);
    add("/semx/regions", &markers);
    add("/semx/path", &paths);
    add("/semx/trajectory", &paths);
    add("/semx/planner_status", &status);
    for (const std::string topic : {"/tf", "/tf_static"}) {
      subs.push_back(nh->subscribe<tf2_msgs::TFMessage>(topic, 100, [this, topic](const tf2_msgs::TFMessage::ConstPtr& m) {
        for (const auto& t : m->transforms) tf[t.header.frame_id + ">" + t.child_frame_id] = t;
        ++count[topic];
      }));
    }
    subs.push_back(nh->subscribe<rosgraph_msgs::Clock>("/clock", 10, [this](const rosgraph_msgs::Clock::ConstPtr& m) {
      clock = m->clock;
      ++count["/clock"];
    }));
  }
  bool all(const std::vector<std::string>& topics) const {
    for (const auto& t : topics) {
      auto it = count.find(t);
      if (it == count.end() || it->second == 0) return false;
    }
    return true;
  }
  std::string missing(const std::vector<std::string>& topics) const {
    std::string s;
    for (const auto& t : topics) {
      auto it = count.find(t);
      if (it == count.end() || it->second == 0) s += t + " ";
    }
    return s;
  }
};

const std::vector<std::string> kMirrorTopics{
    "/semx/odom",     "/semx/camera/depth/image_raw", "/semx/camera/labels/image_raw", "/semx/camera/depth/camera_info",
    "/semx/map",      "/semx/map_free",               "/semx/esdf_slice",              "/semx/roadmap",
    "/semx/regions",  "/semx/path",                   "/semx/trajectory",              "/semx/planner_status",
    "/tf",            "/tf_static",                   "/clock"};

}  // namespace

TEST(RosBridgeLive, MirrorPublishesEveryTopicWithItsTypeFrameAndContent) {
  RosCore core;
  ASSERT_TRUE(core.up()) << core.why();
  auto bridge = start_bridge("bridge_mirror");
  FakeSet set;
  Listener ros;
  ros.subscribe();
  const bool all = spin_until(ros.queue, &set.node, 40, [&] { return ros.all(kMirrorTopics); }, [&] { set.step(); });
  ASSERT_TRUE(all) << "missing: " << ros.missing(kMirrorTopics) << "(bridge log: " << log_dir() << "/bridge_mirror.log)";

  EXPECT_EQ(ros.odom.header.frame_id, "map");
  EXPECT_EQ(ros.odom.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(ros.odom.pose.pose.position.x, 1.0);
  EXPECT_DOUBLE_EQ(ros.odom.pose.pose.position.z, 1.2);
  const auto& depth = ros.images["/semx/camera/depth/image_raw"];
  EXPECT_EQ(depth.header.frame_id, "camera_optical_frame");
  EXPECT_EQ(depth.encoding, "16UC1");
  ASSERT_EQ(depth.data.size(), 2u * 16 * 12);
  const auto expected_depth = set.depth();
  for (std::size_t i = 0; i < expected_depth.size(); ++i) {
    ASSERT_EQ(depth.data[2 * i] | (depth.data[2 * i + 1] << 8), expected_depth[i]) << i;
  }
  EXPECT_EQ(depth.header.stamp.toNSec() % 100000000, 0u) << "a frame's stamp is its tick's time";
  EXPECT_EQ(ros.images["/semx/camera/labels/image_raw"].encoding, "16UC2");
  EXPECT_EQ(ros.infos["/semx/camera/depth/camera_info"].K[0], 8.0);

  std::vector<map::VoxelKey> keys;
  ASSERT_TRUE(rosbridge::voxel_keys(from_ros_msg(ros.clouds["/semx/map"]), 0.1, keys));
  EXPECT_EQ(std::set<map::VoxelKey>(keys.begin(), keys.end()),
            std::set<map::VoxelKey>(set.occupied.begin(), set.occupied.end()));
  EXPECT_EQ(ros.clouds["/semx/map"].header.frame_id, "map");
  EXPECT_EQ(ros.clouds["/semx/map_free"].width, 0u);
  EXPECT_EQ(ros.clouds["/semx/esdf_slice"].width, 12u);
  for (const char* t : {"/semx/roadmap", "/semx/regions"}) {
    ASSERT_FALSE(ros.markers[t].markers.empty()) << t;
    EXPECT_EQ(ros.markers[t].markers.back().header.frame_id, "map") << t;
  }
  EXPECT_EQ(ros.paths["/semx/path"].poses.size(), 2u);
  EXPECT_EQ(ros.paths["/semx/path"].header.frame_id, "map");
  EXPECT_GT(ros.paths["/semx/trajectory"].poses.size(), 5u);
  rosbridge::PlannerStatus st;
  ASSERT_TRUE(rosbridge::status_from_ros(from_ros_msg(ros.status), rosbridge::TimeBase(0), st));
  EXPECT_EQ(st.planner, "semantic-dep");
  EXPECT_EQ(st.reason, "goal 7");

  // The transform tree: map -> base_link -> camera_link -> camera_optical_frame gives the camera's pose.
  ASSERT_TRUE(ros.tf.count("map>base_link"));
  ASSERT_TRUE(ros.tf.count("base_link>camera_link"));
  ASSERT_TRUE(ros.tf.count("camera_link>camera_optical_frame"));
  auto iso = [](const geometry_msgs::TransformStamped& t) {
    const auto m = from_ros_msg(t);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = m.rotation.toRotationMatrix();
    T.translation() = m.translation;
    return T;
  };
  const Eigen::Isometry3d chain =
      iso(ros.tf["map>base_link"]) * iso(ros.tf["base_link>camera_link"]) * iso(ros.tf["camera_link>camera_optical_frame"]);
  EXPECT_LT((chain.matrix() - set.camera_pose().matrix()).cwiseAbs().maxCoeff(), 1e-12);

  // Simulated time: /clock follows SIM_CLOCK and /use_sim_time is set.
  EXPECT_GT(ros.clock.toSec(), 0.0);
  bool sim_time = false;
  EXPECT_TRUE(::ros::param::get("/use_sim_time", sim_time) && sim_time);
  bridge->signal(SIGINT);
  EXPECT_EQ(bridge->wait(10), 0);
}

TEST(RosBridgeLive, TheLcmSideGoesOnWithoutAMasterAndTheBridgeRegistersWithTheNextOne) {
  auto core = std::make_unique<RosCore>();
  ASSERT_TRUE(core->up()) << core->why();
  auto bridge = start_bridge("bridge_restart");
  FakeSet set;
  // The bridge's NODE_STATUS: its LCM side's state and how many messages it handled.
  runtime::Node watcher = make_lcm_node("watcher");
  int8_t state = -1;
  int64_t received = 0;
  std::string detail;
  watcher.subscribe<semx::node_status_t>(channels::NODE_STATUS, [&](const semx::node_status_t& s) {
    if (s.node != "ros_bridge") return;
    state = s.state;
    received = s.received;
    detail = s.detail;
  });
  Listener ros;
  ros.subscribe();
  auto step = [&] {
    set.step();
    watcher.drain();
  };
  ASSERT_TRUE(spin_until(ros.queue, &set.node, 30, [&] { return ros.count["/semx/odom"] > 0; }, step));

  core->stop();
  core.reset();
  const int64_t before = received;
  ASSERT_TRUE(spin_until(ros.queue, &set.node, 20, [&] {
    return state == semx::node_status_t::DEGRADED && received > before + 500;
  }, step)) << "state " << int(state) << " '" << detail << "', received " << received << " (before " << before << ")";
  EXPECT_TRUE(bridge->alive());

  core = std::make_unique<RosCore>();
  ASSERT_TRUE(core->up()) << core->why();
  // This process's node must subscribe anew with the new master too. roscpp keeps one
  // subscription per topic and process, registered with the master it was made with: a second
  // Subscriber beside the first one's would never reach the new master and would only get data
  // through the old link's reconnect to the bridge, whose back-off outlasted the wait on a loaded
  // machine. So the first listener lets go of its topics first (`keep` holds the node up
  // meanwhile: with its last NodeHandle gone roscpp would shut the node down).
  ::ros::NodeHandle keep;
  ros.subs.clear();
  ros.nh.reset();
  Listener again;
  again.subscribe();
  EXPECT_TRUE(spin_until(again.queue, &set.node, 30, [&] {
    return again.count["/semx/odom"] > 0 && again.count["/semx/map"] > 0 && state == semx::node_status_t::RUNNING;
  }, step)) << "after the restart: odom " << again.count["/semx/odom"] << ", map " << again.count["/semx/map"]
              << ", state " << int(state);
  bool sim_time = false;
  EXPECT_TRUE(::ros::param::get("/use_sim_time", sim_time) && sim_time) << "parameters set again";
  bridge->signal(SIGINT);
  EXPECT_EQ(bridge->wait(10), 0);
}

TEST(RosBridgeLive, ExternalModeFeedsSemxFromRosAndSendsSetpoints) {
  RosCore core;
  ASSERT_TRUE(core.up()) << core.why();
  auto bridge = start_bridge("bridge_external", {"--mode", "external", "--set", "setpoints.mode=both"});
  runtime::Node lcm = make_lcm_node("external_test");
  std::vector<semx::odometry_t> odometry;
  std::vector<semx::depth_image_t> depth;
  std::vector<semx::label_image_t> labels;
  std::vector<semx::clock_t> clock;
  lcm.subscribe<semx::odometry_t>(channels::ODOMETRY, [&](const semx::odometry_t& m) { odometry.push_back(m); });
  lcm.subscribe<semx::depth_image_t>(channels::CAMERA_DEPTH, [&](const semx::depth_image_t& m) { depth.push_back(m); });
  lcm.subscribe<semx::label_image_t>(channels::CAMERA_LABELS, [&](const semx::label_image_t& m) { labels.push_back(m); });
  lcm.subscribe<semx::clock_t>(channels::SIM_CLOCK, [&](const semx::clock_t& m) { clock.push_back(m); });

  ::ros::CallbackQueue queue;
  ::ros::NodeHandle nh;
  nh.setCallbackQueue(&queue);
  auto odom_pub = nh.advertise<nav_msgs::Odometry>("/semx/odom", 10);
  auto tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf", 10);
  auto static_pub = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
  auto info_pub = nh.advertise<sensor_msgs::CameraInfo>("/semx/camera/depth/camera_info", 5);
  auto depth_pub = nh.advertise<sensor_msgs::Image>("/semx/camera/depth/image_raw", 5);
  auto label_pub = nh.advertise<sensor_msgs::Image>("/semx/camera/labels/image_raw", 5);
  std::vector<geometry_msgs::TwistStamped> twists;
  std::vector<geometry_msgs::PoseStamped> poses;
  auto twist_sub = nh.subscribe<geometry_msgs::TwistStamped>(
      "/mavros/setpoint_velocity/cmd_vel", 10, [&](const geometry_msgs::TwistStamped::ConstPtr& m) { twists.push_back(*m); });
  auto pose_sub = nh.subscribe<geometry_msgs::PoseStamped>(
      "/mavros/setpoint_position/local", 10, [&](const geometry_msgs::PoseStamped::ConstPtr& m) { poses.push_back(*m); });

  // The vehicle: at (3, -1, 1.5) facing yaw 1.2, flying 0.5 m/s along body x; the camera 10 cm
  // ahead of the body, tilted 0.2 rad down.
  const double yaw = 1.2;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d position(3, -1, 1.5);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.linear() = q.toRotationMatrix();
  body.translation() = position;
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  mount.translation() = Eigen::Vector3d(0.1, 0, 0);
  const Eigen::Isometry3d expected_optical = body * mount * rosbridge::optical_in_camera_link();
  auto tf_of = [](const std::string& parent, const std::string& child, const Eigen::Isometry3d& T, ::ros::Time stamp) {
    rosbridge::msg::TransformStamped t;
    t.header = {rosbridge::from_ros_time(stamp), parent};
    t.child_frame_id = child;
    t.translation = T.translation();
    t.rotation = Eigen::Quaterniond(T.rotation());
    return rosbridge::to_ros_msg(t);
  };
  tf2_msgs::TFMessage statics;
  statics.transforms.push_back(tf_of("base_link", "camera_link", mount, ::ros::Time(0)));
  statics.transforms.push_back(tf_of("camera_link", "camera_optical_frame", rosbridge::optical_in_camera_link(), ::ros::Time(0)));
  static_pub.publish(statics);

  const ::ros::WallTime t0 = ::ros::WallTime::now();
  int sent = 0;
  auto step = [&] {
    const ::ros::Time stamp(::ros::WallTime::now().toSec());
    nav_msgs::Odometry o;
    o.header.stamp = stamp;
    o.header.frame_id = "map";
    o.child_frame_id = "base_link";
    o.pose.pose.position.x = position.x();
    o.pose.pose.position.y = position.y();
    o.pose.pose.position.z = position.z();
    o.pose.pose.orientation.w = q.w();
    o.pose.pose.orientation.z = q.z();
    o.twist.twist.linear.x = 0.5;
    odom_pub.publish(o);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(tf_of("map", "base_link", body, stamp));
    tf_pub.publish(tf);
    if (sent++ % 5 == 0) {
      sensor_msgs::CameraInfo info;
      info.header.stamp = stamp;
      info.header.frame_id = "camera_optical_frame";
      info.width = 16;
      info.height = 12;
      info.K = {8, 0, 8, 0, 8, 6, 0, 0, 1};
      info_pub.publish(info);
      sensor_msgs::Image img;
      img.header = info.header;
      img.width = 16;
      img.height = 12;
      img.encoding = "32FC1";
      img.step = 64;
      img.data.resize(64 * 12);
      for (int i = 0; i < 16 * 12; ++i) {
        const float z = 1.0f + 0.01f * i;
        std::memcpy(&img.data[4 * i], &z, 4);
      }
      depth_pub.publish(img);
      sensor_msgs::Image lab = img;
      lab.encoding = "mono8";
      lab.step = 16;
      lab.data.assign(16 * 12, 7);
      label_pub.publish(lab);
    }
    ::usleep(10000);
  };
  ASSERT_TRUE(spin_until(queue, &lcm, 40, [&] { return odometry.size() > 20 && depth.size() > 3 && labels.size() > 3 && clock.size() > 20; },
                         step))
      << "odometry " << odometry.size() << ", depth " << depth.size() << ", labels " << labels.size() << ", clock "
      << clock.size() << " (bridge log: " << log_dir() << "/bridge_external.log)";
  (void)t0;

  // ODOMETRY: the pose, the body twist as a world velocity.
  const semx::odometry_t& o = odometry.back();
  EXPECT_DOUBLE_EQ(o.position[0], 3.0);
  EXPECT_NEAR(o.velocity[0], 0.5 * std::cos(yaw), 1e-12);
  EXPECT_NEAR(o.velocity[1], 0.5 * std::sin(yaw), 1e-12);
  // CAMERA_DEPTH: millimetres, and the optical frame's pose from the TF tree at the image's stamp.
  const semx::depth_image_t& d = depth.back();
  runtime::PinholeCamera camera;
  Eigen::Isometry3d pose;
  ASSERT_EQ(runtime::from_camera_info(d.info, camera, pose), "");
  EXPECT_LT((pose.matrix() - expected_optical.matrix()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(camera.fx, 8.0);
  std::vector<uint16_t> mm;
  ASSERT_EQ(runtime::decode_u16_image(d.compression, d.depth_data, 16 * 12, mm), "");
  EXPECT_EQ(mm[0], 1000);
  EXPECT_EQ(mm[100], 2000);
  // Labels pair with their depth frame.
  bool paired = false;
  for (const auto& l : labels) paired = paired || l.info.frame_id == d.info.frame_id;
  EXPECT_TRUE(paired);
  // SIM_CLOCK: REALTIME, on the sensors' time (origin: the first stamp's whole second).
  EXPECT_EQ(clock.back().mode, semx::clock_t::REALTIME);
  EXPECT_GE(clock.back().utime, o.utime - 300000);
  EXPECT_LE(clock.back().utime, o.utime + 300000);

  // CONTROL_CMD -> TwistStamped on MAVROS's topic; TRAJECTORY -> position setpoints.
  semx::control_cmd_t c{};
  c.utime = o.utime;
  c.mode = semx::control_cmd_t::VELOCITY;
  c.setpoint[0] = 0.4;
  c.setpoint[1] = -0.2;
  c.yaw_mode = semx::control_cmd_t::YAW_ANGLE;
  c.yaw = yaw + 0.1;
  semx::trajectory_t t{};
  t.utime = o.utime;
  t.start_utime = o.utime;
  t.degree = 3;
  t.knot_interval = 0.5;
  for (int i = 0; i < 6; ++i) {
    t.control_points.push_back({7.0, 8.0, 1.0});
    t.yaw_control_points.push_back(0.0);
  }
  t.num_control_points = 6;
  ASSERT_TRUE(spin_until(queue, &lcm, 20, [&] { return !twists.empty() && !poses.empty() && poses.back().pose.position.x == 7.0; },
                         [&] {
                           step();
                           lcm.publish(channels::CONTROL_CMD, c);
                           lcm.publish(channels::TRAJECTORY, t);
                         }))
      << "twists " << twists.size() << ", poses " << poses.size();
  EXPECT_EQ(twists.back().header.frame_id, "map");
  EXPECT_DOUBLE_EQ(twists.back().twist.linear.x, 0.4);
  EXPECT_DOUBLE_EQ(twists.back().twist.linear.y, -0.2);
  EXPECT_NEAR(twists.back().twist.angular.z, 1.5 * 0.1, 1e-9);
  EXPECT_DOUBLE_EQ(poses.back().pose.position.y, 8.0);
  bridge->signal(SIGINT);
  EXPECT_EQ(bridge->wait(10), 0);
}
