// The bridge's mapping between semx values and ROS messages (as plain structs, no ROS needed):
// every message type out and back equal within float precision, and the conventions (frames,
// units, encodings, reserved values) checked one by one.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <thread>

#include "semx/core/angles.hpp"
#include "semx/core/states.hpp"
#include "semx/runtime/semantic_classes.hpp"
#include "semx/ros/bounded_queue.hpp"
#include "semx/ros/bridge_config.hpp"
#include "semx/ros/camera_conversion.hpp"
#include "semx/ros/cloud_conversion.hpp"
#include "semx/ros/marker_conversion.hpp"
#include "semx/ros/odometry_conversion.hpp"
#include "semx/ros/path_conversion.hpp"
#include "semx/ros/setpoint_conversion.hpp"
#include "semx/ros/status_conversion.hpp"

using namespace semx;
using namespace semx::rosbridge;

namespace {

const FrameNames kFrames;

Eigen::Quaterniond random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

Eigen::Vector3d random_vector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

void expect_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol, const char* what) {
  EXPECT_LE((a - b).norm(), tol) << what << ": " << a.transpose() << " vs " << b.transpose();
}

void expect_same_rotation(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double tol) {
  EXPECT_LT(a.angularDistance(b), tol);
}

CameraShot test_shot(int64_t utime = 1230000) {
  CameraShot s;
  s.utime = utime;
  s.frame_id = 7;
  s.camera.width = 8;
  s.camera.height = 6;
  s.camera.fx = 4.5;
  s.camera.fy = 4.25;
  s.camera.cx = 4.0;
  s.camera.cy = 3.0;
  s.T_world_optical.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                runtime::optical_in_body());
  s.T_world_optical.translation() = Eigen::Vector3d(1.5, -2.0, 1.2);
  return s;
}

controller::Trajectory test_trajectory() {
  controller::PositionSpline::Points q;
  controller::YawSpline::Points y;
  for (int i = 0; i < 8; ++i) {
    q.emplace_back(0.3 * i, 0.1 * i * i, 1.0 + 0.05 * i);
    controller::YawSpline::Point p;
    p(0) = 0.4 * i;  // unwrapped past pi
    y.push_back(p);
  }
  controller::Trajectory t;
  t.plan_id = 3;
  t.start_utime = 4000000;
  t.position = controller::PositionSpline(q, 0.25);
  t.yaw = controller::YawSpline(y, 0.25);
  return t;
}

}  // namespace

TEST(RosTime, OriginIsTheFirstStampFlooredAndUtimeRoundTrips) {
  TimeBase sim(0);
  EXPECT_EQ(sim.to_ros_ns(1234567), 1234567000);
  int64_t u = 0;
  ASSERT_TRUE(sim.to_utime(1234567400, u));
  EXPECT_EQ(u, 1234567);
  ASSERT_TRUE(sim.to_utime(1234567600, u));
  EXPECT_EQ(u, 1234568);  // nearest microsecond

  TimeBase wall;
  EXPECT_FALSE(wall.known());
  EXPECT_FALSE(wall.adopt(0));
  ASSERT_TRUE(wall.adopt(1700000123456789012));
  EXPECT_EQ(wall.origin_ns(), 1700000123000000000);
  EXPECT_TRUE(wall.adopt(5));  // fixed once
  EXPECT_EQ(wall.origin_ns(), 1700000123000000000);
  ASSERT_TRUE(wall.to_utime(1700000124500000000, u));
  EXPECT_EQ(u, 1500000);
  EXPECT_EQ(wall.to_ros_ns(u), 1700000124500000000);
  EXPECT_FALSE(wall.to_utime(1700000122000000000, u)) << "before the origin";
}

TEST(RosOdometry, OutAndBackEqualWithTheTwistInTheBodyFrame) {
  std::mt19937 rng(3);
  for (int i = 0; i < 50; ++i) {
    VehicleOdometry o;
    o.utime = 1000000 + 10000 * i;
    o.position = random_vector(rng, 20);
    o.orientation = random_rotation(rng);
    o.velocity = random_vector(rng, 2);
    o.angular_velocity = random_vector(rng, 1);
    const msg::Odometry m = to_ros(o, kFrames, TimeBase(0));
    EXPECT_EQ(m.header.frame_id, "map");
    EXPECT_EQ(m.child_frame_id, "base_link");
    expect_near(m.twist.linear, o.orientation.conjugate() * o.velocity, 1e-12, "body-frame twist");
    VehicleOdometry back;
    ASSERT_EQ(from_ros(m, TimeBase(0), back), "");
    EXPECT_EQ(back.utime, o.utime);
    expect_near(back.position, o.position, 1e-12, "position");
    expect_same_rotation(back.orientation, o.orientation, 1e-12);
    expect_near(back.velocity, o.velocity, 1e-12, "velocity");
    expect_near(back.angular_velocity, o.angular_velocity, 1e-12, "rates");
    const msg::TransformStamped t = body_transform(o, kFrames, TimeBase(0));
    EXPECT_EQ(t.header.frame_id, "map");
    EXPECT_EQ(t.child_frame_id, "base_link");
    expect_near(t.translation, o.position, 0, "tf");
  }
  // Flying forward while facing +y (yaw 90 deg): the world velocity is +y, the body's twist +x.
  VehicleOdometry o;
  o.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(core::kPi / 2, Eigen::Vector3d::UnitZ()));
  o.velocity = {0, 1, 0};
  expect_near(to_ros(o, kFrames, TimeBase(0)).twist.linear, {1, 0, 0}, 1e-12, "forward");
}

TEST(RosOdometry, RefusesWhatIsNotAPose) {
  msg::Odometry m;
  VehicleOdometry o;
  m.pose.orientation = Eigen::Quaterniond(2, 0, 0, 0);
  EXPECT_NE(from_ros(m, TimeBase(0), o), "");
  m.pose.orientation = Eigen::Quaterniond::Identity();
  m.pose.position.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(from_ros(m, TimeBase(0), o), "");
  m.pose.position.x() = 0;
  m.header.stamp_ns = 5;
  EXPECT_NE(from_ros(m, TimeBase(1000000000), o), "") << "before the time origin";
  EXPECT_EQ(from_ros(m, TimeBase(0), o), "");
}

TEST(RosOdometry, APoseStreamGetsItsVelocityAndRatesByDifference) {
  PoseDifferentiator d;
  VehicleOdometry o;
  const Eigen::Vector3d v(0.5, -0.2, 0.1);
  const double yaw_rate = 0.4;
  for (int i = 0; i < 5; ++i) {
    msg::PoseStamped p;
    p.header.stamp_ns = 1000000000 + i * 50000000LL;  // 20 Hz
    p.pose.position = Eigen::Vector3d(1, 2, 3) + v * (0.05 * i);
    p.pose.orientation = yaw_quaternion(yaw_rate * 0.05 * i);
    ASSERT_EQ(d.convert(p, TimeBase(0), o), "");
    if (i == 0) {
      expect_near(o.velocity, Eigen::Vector3d::Zero(), 0, "first pose");
    } else {
      expect_near(o.velocity, v, 1e-9, "velocity");
      expect_near(o.angular_velocity, {0, 0, yaw_rate}, 1e-9, "rates");
    }
  }
  // A gap longer than max_gap_s: no velocity from it.
  msg::PoseStamped late;
  late.header.stamp_ns = 1000000000 + 4 * 50000000LL + 2000000000LL;
  late.pose.position = {9, 9, 9};
  ASSERT_EQ(d.convert(late, TimeBase(0), o), "");
  expect_near(o.velocity, Eigen::Vector3d::Zero(), 0, "after a gap");
}

TEST(RosCamera, DepthOutAndBackIsExactWithTheReservedValues) {
  DepthFrame f;
  f.shot = test_shot();
  const std::size_t n = 48;
  for (std::size_t i = 0; i < n; ++i) f.depth_mm.push_back(static_cast<uint16_t>(500 + 1237 * i));
  f.depth_mm[3] = runtime::kDepthInvalid;
  f.depth_mm[4] = runtime::kDepthNoReturn;
  const msg::Image m = to_ros(f, kFrames, TimeBase(0));
  EXPECT_EQ(m.encoding, "16UC1");
  EXPECT_EQ(m.header.frame_id, "camera_optical_frame");
  EXPECT_EQ(m.header.stamp_ns, 1230000000);
  EXPECT_EQ(m.step, 16u);
  EXPECT_EQ(m.data[2], f.depth_mm[1] & 0xFF) << "little-endian";
  DepthFrame back;
  ASSERT_EQ(from_ros(m, f.shot, back), "");
  EXPECT_EQ(back.depth_mm, f.depth_mm);
}

TEST(RosCamera, DepthInMetresFollowsRep118) {
  const CameraShot shot = test_shot();
  msg::Image m;
  m.width = 8;
  m.height = 6;
  m.encoding = "32FC1";
  m.step = 8 * 4 + 4;  // padded rows
  m.data.assign(m.step * m.height, 0);
  auto put = [&](int u, int v, float z) { std::memcpy(&m.data[v * m.step + 4 * u], &z, 4); };
  put(0, 0, 1.2344f);
  put(1, 0, std::numeric_limits<float>::quiet_NaN());
  put(2, 0, std::numeric_limits<float>::infinity());
  put(3, 0, -std::numeric_limits<float>::infinity());
  put(4, 0, 70.0f);
  put(7, 5, 2.5f);
  DepthFrame f;
  ASSERT_EQ(from_ros(m, shot, f), "");
  EXPECT_EQ(f.depth_mm[0], 1234);
  EXPECT_EQ(f.depth_mm[1], runtime::kDepthInvalid);
  EXPECT_EQ(f.depth_mm[2], runtime::kDepthNoReturn);
  EXPECT_EQ(f.depth_mm[3], runtime::kDepthInvalid);
  EXPECT_EQ(f.depth_mm[4], runtime::kDepthMaxEncodable);
  EXPECT_EQ(f.depth_mm[5], runtime::kDepthInvalid);  // 0.0
  EXPECT_EQ(f.depth_mm[47], 2500);

  // Big-endian 16UC1, and images that do not fit the CameraInfo.
  msg::Image b;
  b.width = 8;
  b.height = 6;
  b.encoding = "16UC1";
  b.is_bigendian = true;
  b.step = 16;
  b.data.assign(96, 0);
  b.data[0] = 0x04;
  b.data[1] = 0xD2;
  ASSERT_EQ(from_ros(b, shot, f), "");
  EXPECT_EQ(f.depth_mm[0], 1234);
  b.width = 9;
  EXPECT_NE(from_ros(b, shot, f), "");
  b.width = 8;
  b.data.resize(95);
  EXPECT_NE(from_ros(b, shot, f), "");
  b.data.resize(96);
  b.encoding = "bgr8";
  EXPECT_NE(from_ros(b, shot, f), "");
}

TEST(RosCamera, LabelsOutAndBackAndClassOnlyImagesIn) {
  LabelFrame f;
  f.shot = test_shot();
  for (int i = 0; i < 48; ++i) {
    f.classes.push_back(static_cast<uint16_t>(i % 20));
    f.instances.push_back(static_cast<uint16_t>(65000 + i));
  }
  const msg::Image m = to_ros(f, kFrames, TimeBase(0));
  EXPECT_EQ(m.encoding, "16UC2");
  LabelFrame back;
  ASSERT_EQ(from_ros(m, f.shot, back), "");
  EXPECT_EQ(back.classes, f.classes);
  EXPECT_EQ(back.instances, f.instances);

  msg::Image mono;
  mono.width = 8;
  mono.height = 6;
  mono.encoding = "mono8";
  mono.step = 8;
  for (int i = 0; i < 48; ++i) mono.data.push_back(static_cast<uint8_t>(i % 20));
  ASSERT_EQ(from_ros(mono, f.shot, back), "");
  EXPECT_EQ(back.classes, f.classes);
  EXPECT_EQ(back.instances, std::vector<uint16_t>(48, 0));
}

TEST(RosCamera, RgbOutAndBackAndBgrIn) {
  RgbFrame f;
  f.shot = test_shot();
  for (int i = 0; i < 48 * 3; ++i) f.rgb.push_back(static_cast<uint8_t>(i * 7));
  msg::Image m = to_ros(f, kFrames, TimeBase(0));
  EXPECT_EQ(m.encoding, "rgb8");
  RgbFrame back;
  ASSERT_EQ(from_ros(m, f.shot, back), "");
  EXPECT_EQ(back.rgb, f.rgb);
  for (int i = 0; i < 48; ++i) std::swap(m.data[3 * i], m.data[3 * i + 2]);
  m.encoding = "bgr8";
  ASSERT_EQ(from_ros(m, f.shot, back), "");
  EXPECT_EQ(back.rgb, f.rgb);
}

TEST(RosCamera, CameraInfoOutAndBackAndDistortionRefused) {
  const CameraShot shot = test_shot();
  msg::CameraInfo info = to_ros_info(shot, kFrames, TimeBase(0));
  EXPECT_EQ(info.header.frame_id, "camera_optical_frame");
  EXPECT_EQ(info.K[0], 4.5);
  EXPECT_EQ(info.P[6], 3.0);
  runtime::PinholeCamera c;
  ASSERT_EQ(camera_from_ros(info, 0.3, 4.0, c), "");
  EXPECT_EQ(c.width, 8);
  EXPECT_EQ(c.height, 6);
  EXPECT_EQ(c.fx, shot.camera.fx);
  EXPECT_EQ(c.fy, shot.camera.fy);
  EXPECT_EQ(c.cx, shot.camera.cx);
  EXPECT_EQ(c.cy, shot.camera.cy);
  EXPECT_EQ(c.min_range, 0.3);
  EXPECT_EQ(c.max_range, 4.0);
  info.D[0] = 0.01;
  EXPECT_NE(camera_from_ros(info, 0.3, 4.0, c), "");
  info.D[0] = 0.0;
  info.K[0] = 0.0;
  EXPECT_NE(camera_from_ros(info, 0.3, 4.0, c), "");
}

TEST(RosCamera, TheTransformChainGivesTheOpticalFrameBack) {
  std::mt19937 rng(5);
  for (int i = 0; i < 20; ++i) {
    CameraShot shot = test_shot();
    shot.T_world_optical.linear() = random_rotation(rng).toRotationMatrix();
    shot.T_world_optical.translation() = random_vector(rng, 10);
    Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
    body.linear() = random_rotation(rng).toRotationMatrix();
    body.translation() = random_vector(rng, 10);
    const msg::TransformStamped mount = camera_transform(shot, body, kFrames, TimeBase(0));
    const msg::TransformStamped optical = optical_transform(kFrames, 0);
    EXPECT_EQ(mount.header.frame_id, "base_link");
    EXPECT_EQ(mount.child_frame_id, "camera_link");
    EXPECT_EQ(optical.header.frame_id, "camera_link");
    EXPECT_EQ(optical.child_frame_id, "camera_optical_frame");
    auto iso = [](const msg::TransformStamped& t) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = t.rotation.toRotationMatrix();
      T.translation() = t.translation;
      return T;
    };
    const Eigen::Isometry3d chain = body * iso(mount) * iso(optical);
    EXPECT_LT((chain.matrix() - shot.T_world_optical.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
  // REP 103: the optical frame's z is camera_link's x (forward), its x is -y (right), its y is -z.
  const Eigen::Matrix3d R = optical_in_camera_link().rotation();
  expect_near(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), 1e-15, "optical z");
  expect_near(R * Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(), 1e-15, "optical x");
  expect_near(R * Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ(), 1e-15, "optical y");
}

TEST(RosMap, VoxelCloudsGiveTheirKeysBack) {
  map::StateGrid grid(0.1);
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> k(-300, 300);
  std::set<map::VoxelKey> occupied, free;
  for (int i = 0; i < 3000; ++i) {
    const map::VoxelKey key(k(rng), k(rng), k(rng) / 10);
    const bool occ = i % 3 == 0;
    grid.set_state(key, occ ? map::VoxelState::kOccupied : map::VoxelState::kFree);
    (occ ? occupied : free).insert(key);
    (occ ? free : occupied).erase(key);
  }
  for (auto [state, expected] : {std::pair{map::VoxelState::kOccupied, &occupied}, {map::VoxelState::kFree, &free}}) {
    const msg::PointCloud2 c = voxel_cloud(grid, state, "map", 42);
    EXPECT_EQ(c.header.frame_id, "map");
    EXPECT_EQ(c.width, expected->size());
    EXPECT_EQ(c.point_step, 12u);
    std::vector<map::VoxelKey> keys;
    ASSERT_TRUE(voxel_keys(c, 0.1, keys));
    EXPECT_EQ(std::set<map::VoxelKey>(keys.begin(), keys.end()), *expected);
  }
  // Clipped: only voxels whose centre is at most max_z high.
  std::vector<map::VoxelKey> low;
  ASSERT_TRUE(voxel_keys(voxel_cloud(grid, map::VoxelState::kOccupied, "map", 42, 1.0), 0.1, low));
  std::size_t expected_low = 0;
  for (const auto& k : occupied) expected_low += (k.z + 0.5) * 0.1 <= 1.0;
  EXPECT_EQ(low.size(), expected_low);
  EXPECT_GT(expected_low, 0u);
  EXPECT_LT(expected_low, occupied.size());
  for (const auto& k : low) EXPECT_LE(k.z, 9);
  msg::PointCloud2 bad = voxel_cloud(grid, map::VoxelState::kOccupied, "map", 0);
  bad.data.resize(bad.data.size() - 1);
  std::vector<map::VoxelKey> keys;
  EXPECT_FALSE(voxel_keys(bad, 0.1, keys));
}

TEST(RosMap, EsdfSliceCarriesTheLayerAtTheHeight) {
  map::EsdfGrid g;
  g.resolution = 0.1;
  g.origin = map::VoxelKey(-20, 5, 3);
  g.nx = 7;
  g.ny = 5;
  g.nz = 4;
  for (int i = 0; i < g.nx * g.ny * g.nz; ++i) g.distance.push_back(0.01f * i - 0.3f);
  const double z = (3 + 2 + 0.3) * 0.1;  // inside layer 2
  const msg::PointCloud2 c = esdf_slice(g, z, "map", 9);
  std::vector<SlicePoint> points;
  ASSERT_TRUE(slice_points(c, points));
  ASSERT_EQ(points.size(), 35u);
  for (const auto& p : points) {
    const map::VoxelKey key(static_cast<int>(std::floor(p.position.x() / 0.1)),
                            static_cast<int>(std::floor(p.position.y() / 0.1)),
                            static_cast<int>(std::floor(p.position.z() / 0.1)));
    EXPECT_EQ(key.z, 5);
    float d = 0;
    ASSERT_TRUE(g.voxel_distance(key, &d));
    EXPECT_EQ(p.distance, d);
  }
  // Beyond the window: the nearest layer.
  ASSERT_TRUE(slice_points(esdf_slice(g, 100.0, "map", 9), points));
  EXPECT_NEAR(points[0].position.z(), (3 + 3 + 0.5) * 0.1, 1e-6);
}

TEST(RosMarkers, RoadmapOutAndBack) {
  Roadmap r;
  std::mt19937 rng(2);
  for (int i = 0; i < 30; ++i) {
    RoadmapNode n;
    n.id = 100 + i;
    n.position = random_vector(rng, 8);
    n.score = i * 0.5;
    n.flags = i % 7 == 0 ? RoadmapNode::kOnPath : 0;
    r.nodes.push_back(n);
  }
  for (int i = 1; i < 30; ++i) r.edges.emplace_back(100 + i - 1, 100 + i);
  r.edges.emplace_back(100, 129);
  const msg::MarkerArray a = roadmap_markers(r, "map", 77);
  EXPECT_EQ(a.markers.front().action, msg::Marker::DELETEALL);
  for (const auto& m : a.markers) EXPECT_EQ(m.header.frame_id, "map");
  Roadmap back;
  ASSERT_TRUE(roadmap_from_markers(a, back));
  ASSERT_EQ(back.nodes.size(), r.nodes.size());
  for (std::size_t i = 0; i < r.nodes.size(); ++i) {
    EXPECT_EQ(back.nodes[i].position, r.nodes[i].position);
    EXPECT_EQ((back.nodes[i].flags & RoadmapNode::kOnPath) != 0, (r.nodes[i].flags & RoadmapNode::kOnPath) != 0);
  }
  ASSERT_EQ(back.edges.size(), r.edges.size());
  for (std::size_t i = 0; i < r.edges.size(); ++i) {
    EXPECT_EQ(back.edges[i].first + 100, r.edges[i].first);
    EXPECT_EQ(back.edges[i].second + 100, r.edges[i].second);
  }
  // Edges faded, scores on a ramp from the lowest to the highest.
  for (const auto& m : a.markers) {
    if (m.type == msg::Marker::LINE_LIST) {
      EXPECT_LT(m.color.a, 0.5f);
    }
  }
  const msg::Color lo = score_color(0, 0, 1), hi = score_color(1, 0, 1);
  EXPECT_GT(hi.r + hi.g, lo.r + lo.g);
  // An empty roadmap clears the display.
  Roadmap empty;
  ASSERT_TRUE(roadmap_from_markers(roadmap_markers(empty, "map", 0), back));
  EXPECT_TRUE(back.nodes.empty());
}

TEST(RosMarkers, RegionsOutAndBack) {
  std::vector<Region> regions;
  for (int i = 0; i < 6; ++i) {
    Region g;
    g.id = 11 + i;
    g.class_id = 5 + i;  // chair, table, sofa, bed, cabinet, shelf
    g.label = std::string(runtime::class_info(*runtime::class_from_id(g.class_id)).name);
    g.centroid = {0.5 * i, -1.0 * i, 0.7};
    g.radius = 0.4 + 0.1 * i;
    g.active = i % 2 == 0;
    regions.push_back(g);
  }
  const msg::MarkerArray a = region_markers(regions, "map", 5);
  std::vector<Region> back;
  ASSERT_TRUE(regions_from_markers(a, back));
  ASSERT_EQ(back.size(), regions.size());
  for (std::size_t i = 0; i < regions.size(); ++i) {
    EXPECT_EQ(back[i].id, regions[i].id);
    EXPECT_EQ(back[i].class_id, regions[i].class_id);
    EXPECT_EQ(back[i].label, regions[i].label);
    EXPECT_EQ(back[i].centroid, regions[i].centroid);
    EXPECT_DOUBLE_EQ(back[i].radius, regions[i].radius);
    EXPECT_EQ(back[i].active, regions[i].active);
  }
}

TEST(RosPaths, PathOutAndBack) {
  controller::Path p;
  p.utime = 2500000;
  p.waypoints = {{0, 0, 1}, {1, 0.5, 1.2}, {2, -1, 0.8}};
  p.yaws = {0.0, 3.0, -2.5};
  const msg::Path m = to_ros(p, "map", TimeBase(0));
  EXPECT_EQ(m.header.frame_id, "map");
  EXPECT_EQ(m.header.stamp_ns, 2500000000);
  controller::Path back;
  ASSERT_TRUE(path_from_ros(m, back));
  ASSERT_EQ(back.waypoints.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    expect_near(back.waypoints[i], p.waypoints[i], 0, "waypoint");
    EXPECT_NEAR(back.yaws[i], p.yaws[i], 1e-12);
  }
}

TEST(RosPaths, TrajectorySamplesAreTheSplines) {
  const controller::Trajectory t = test_trajectory();
  const msg::Path m = to_ros(t, 0.1, "map", TimeBase(0));
  std::vector<TimedPose> poses;
  ASSERT_TRUE(trajectory_from_ros(m, TimeBase(0), poses));
  ASSERT_GE(poses.size(), 2u);
  EXPECT_EQ(poses.front().utime, t.start_utime);
  EXPECT_EQ(poses.back().utime, t.start_utime + static_cast<int64_t>(std::llround(t.duration() * 1e6)));
  for (const auto& p : poses) {
    const controller::TrajectoryPoint s = t.sample(t.time_at(p.utime));
    expect_near(p.position, s.position, 1e-9, "sample");
    EXPECT_NEAR(core::wrap_angle(p.yaw - s.yaw), 0.0, 1e-9);
  }
}

TEST(RosStatus, PlannerStatusOutAndBackExactly) {
  PlannerStatus s;
  s.utime = 12345678;
  s.planner = "semantic-dep";
  s.state = static_cast<int>(core::PlannerState::kRecovering);
  s.reason = "no path: goal unreachable";
  s.iteration = 42;
  s.num_nodes = 310;
  s.num_edges = 1202;
  s.goal = {1.0 / 3.0, -2.5, 1.1};
  s.best_gain = 1234.5678901234;
  s.best_reward = 0.1 + 0.2;
  s.best_score = 1e-17;
  s.total_ms = 17.25;
  s.charged_s = 0.1;
  const msg::DiagnosticArray a = to_ros(s, TimeBase(0));
  ASSERT_EQ(a.status.size(), 1u);
  EXPECT_EQ(a.status[0].level, msg::DiagnosticStatus::WARN);
  EXPECT_EQ(a.status[0].message, "RECOVERING: no path: goal unreachable");
  PlannerStatus b;
  ASSERT_TRUE(status_from_ros(a, TimeBase(0), b));
  EXPECT_EQ(b.utime, s.utime);
  EXPECT_EQ(b.planner, s.planner);
  EXPECT_EQ(b.state, s.state);
  EXPECT_EQ(b.reason, s.reason);
  EXPECT_EQ(b.iteration, s.iteration);
  EXPECT_EQ(b.num_nodes, s.num_nodes);
  EXPECT_EQ(b.num_edges, s.num_edges);
  EXPECT_EQ(b.goal, s.goal);
  EXPECT_EQ(b.best_gain, s.best_gain);
  EXPECT_EQ(b.best_reward, s.best_reward);
  EXPECT_EQ(b.best_score, s.best_score);
  EXPECT_EQ(b.total_ms, s.total_ms);
  EXPECT_EQ(b.charged_s, s.charged_s);
  s.state = static_cast<int>(core::PlannerState::kFailed);
  EXPECT_EQ(to_ros(s, TimeBase(0)).status[0].level, msg::DiagnosticStatus::ERROR);
}

TEST(RosSetpoints, VelocityWithTheHeadingAsARate) {
  SetpointConfig cfg;
  VehicleCommand c;
  c.utime = 3000000;
  c.mode = VehicleCommand::Mode::kVelocity;
  c.setpoint = {0.4, -0.3, 0.1};
  c.yaw = 0.2;
  msg::TwistStamped t = velocity_setpoint(c, 0.1, cfg, "map", TimeBase(0));
  EXPECT_EQ(t.header.frame_id, "map");
  expect_near(t.twist.linear, c.setpoint, 0, "velocity");
  EXPECT_NEAR(t.twist.angular.z(), cfg.yaw_gain * 0.1, 1e-12);
  // Across +-pi the short way round, and limited.
  c.yaw = 3.1;
  t = velocity_setpoint(c, -3.1, cfg, "map", TimeBase(0));
  EXPECT_NEAR(t.twist.angular.z(), cfg.yaw_gain * (6.2 - 2 * core::kPi), 1e-9);  // through -pi
  c.yaw = 2.0;
  EXPECT_EQ(velocity_setpoint(c, -1.0, cfg, "map", TimeBase(0)).twist.angular.z(), cfg.max_yaw_rate);
  EXPECT_EQ(velocity_setpoint(c, 5.0, cfg, "map", TimeBase(0)).twist.angular.z(), -cfg.max_yaw_rate);
  EXPECT_EQ(velocity_setpoint(c, std::nullopt, cfg, "map", TimeBase(0)).twist.angular.z(), 0.0);
  c.mode = VehicleCommand::Mode::kHold;
  expect_near(velocity_setpoint(c, 2.0, cfg, "map", TimeBase(0)).twist.linear, Eigen::Vector3d::Zero(), 0, "hold");
  // Back: a velocity command with a yaw rate.
  c.mode = VehicleCommand::Mode::kVelocity;
  c.yaw_mode = VehicleCommand::YawMode::kRate;
  c.yaw_rate = 0.35;
  const VehicleCommand b = command_from_ros(velocity_setpoint(c, std::nullopt, cfg, "map", TimeBase(0)), TimeBase(0));
  EXPECT_EQ(b.utime, c.utime);
  EXPECT_EQ(b.mode, VehicleCommand::Mode::kVelocity);
  expect_near(b.setpoint, c.setpoint, 0, "back");
  EXPECT_EQ(b.yaw_rate, 0.35);
}

TEST(RosSetpoints, PositionIsTheTrajectoryALittleAhead) {
  const controller::Trajectory t = test_trajectory();
  SetpointConfig cfg;
  cfg.lead_s = 0.3;
  const int64_t now = t.start_utime + 500000;
  const msg::PoseStamped p = position_setpoint(t, now, cfg, "map", TimeBase(0));
  const controller::TrajectoryPoint s = t.sample(0.8);
  expect_near(p.pose.position, s.position, 1e-12, "ahead");
  EXPECT_NEAR(core::wrap_angle(quaternion_yaw(p.pose.orientation) - s.yaw), 0.0, 1e-12);
  const msg::PoseStamped end = position_setpoint(t, t.start_utime + 100000000, cfg, "map", TimeBase(0));
  expect_near(end.pose.position, t.end_position(), 1e-12, "end");
}

TEST(RosQueue, DropsTheOldestAndNeverBlocks) {
  BoundedQueue<int> q(3);
  for (int i = 0; i < 5; ++i) q.push(i);
  EXPECT_EQ(q.dropped(), 2);
  EXPECT_EQ(q.take_all(), (std::vector<int>{2, 3, 4}));
  EXPECT_TRUE(q.take_all().empty());
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    q.push(9);
  });
  const auto got = q.take_all(std::chrono::milliseconds(2000));
  producer.join();
  EXPECT_EQ(got, std::vector<int>{9});
}

TEST(RosConfig, TheShippedYamlIsExactlyTheDefaultsAndErrorsNameTheKey) {
  const BridgeConfig d;
  const auto f = runtime::load_config<BridgeConfig>(std::string(SEMX_SOURCE_DIR) + "/ros/config/bridge.yaml");
#define SAME(field) EXPECT_EQ(f.field, d.field) << #field
  SAME(mode);
  SAME(node_name);
  SAME(frames.map);
  SAME(frames.body);
  SAME(frames.camera);
  SAME(frames.optical);
  SAME(out.odom);
  SAME(out.map);
  SAME(out.map_free);
  SAME(out.esdf_slice);
  SAME(out.roadmap);
  SAME(out.regions);
  SAME(out.path);
  SAME(out.trajectory);
  SAME(out.planner_status);
  SAME(out.depth);
  SAME(out.depth_info);
  SAME(out.labels);
  SAME(out.labels_info);
  SAME(out.rgb);
  SAME(out.rgb_info);
  SAME(in.odom);
  SAME(in.odom_type);
  SAME(in.depth);
  SAME(in.camera_info);
  SAME(in.labels);
  SAME(in.min_range);
  SAME(in.max_range);
  SAME(in.tf_timeout_s);
  SAME(in.publish_body_tf);
  SAME(setpoints.mode);
  SAME(setpoints.velocity_topic);
  SAME(setpoints.position_topic);
  SAME(setpoints.conversion.yaw_gain);
  SAME(setpoints.conversion.max_yaw_rate);
  SAME(setpoints.conversion.lead_s);
  SAME(rates.map_hz);
  SAME(rates.map_free_hz);
  SAME(rates.esdf_hz);
  SAME(rates.trajectory_dt);
  SAME(rates.esdf_slice_offset);
  SAME(rates.map_max_z);
  SAME(camera);
  SAME(publish_clock);
  SAME(queue_frames);
  SAME(queue_messages);
  SAME(master_check_s);
  SAME(clock_period_s);
#undef SAME
  // The MAVROS example differs where it says it does, and loads.
  const auto mavros = runtime::load_config<BridgeConfig>(std::string(SEMX_SOURCE_DIR) + "/ros/config/mavros.yaml");
  EXPECT_EQ(mavros.mode, BridgeMode::kExternal);
  EXPECT_EQ(mavros.in.odom, "/mavros/local_position/odom");

  try {
    runtime::load_config<BridgeConfig>("", {"setpoints.mode=sideways"});
    FAIL() << "accepted a mode that does not exist";
  } catch (const runtime::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("mode"), std::string::npos) << e.what();
  }
  EXPECT_THROW(runtime::load_config<BridgeConfig>("", {"in.max_range=0.2"}), runtime::ConfigError);
  EXPECT_THROW(runtime::load_config<BridgeConfig>("", {"out.map="}), runtime::ConfigError);
  EXPECT_THROW(runtime::load_config<BridgeConfig>("", {"frames.mapp=x"}), runtime::ConfigError);
}
