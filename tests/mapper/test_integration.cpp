// Ray casting of depth frames into the occupancy map.
#include <gtest/gtest.h>

#include <octomap/OcTree.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "mapper_test_util.hpp"
#include "semx/mapper/map_export.hpp"

namespace semx::mapper {
namespace {

using test::axis_camera;
using test::looking_along_x;

constexpr IntegrationParams::Mode kAllModes[] = {
    IntegrationParams::Mode::kExact, IntegrationParams::Mode::kBundled, IntegrationParams::Mode::kFast};

// One pixel looking along +x from the centre of voxel (0, 0, 0).
struct SingleRay {
  explicit SingleRay(IntegrationParams::Mode mode = IntegrationParams::Mode::kBundled)
      : config(test::config_with_mode(mode)), mapper(config) {}
  FrameResult shoot(uint16_t depth_mm) {
    depth = {depth_mm};
    return mapper.integrate(DepthFrame::view(cam, looking_along_x({0.05, 0.05, 0.05}), depth));
  }
  MapperConfig config;
  Mapper mapper;
  runtime::PinholeCamera cam = axis_camera();
  std::vector<uint16_t> depth;
};

TEST(Integration, SingleRayMarksFreeCellsAndTheEndCell) {
  for (auto mode : kAllModes) {
    SingleRay r(mode);
    const FrameResult res = r.shoot(1000);  // ends at x = 1.05: voxel 10
    ASSERT_TRUE(res.report.accepted) << res.report.error;
    const OccupancyMap& map = r.mapper.map();
    for (int x = 0; x < 10; ++x) {
      EXPECT_EQ(map.state(map::VoxelKey{x, 0, 0}), map::VoxelState::kFree) << "x=" << x;
      EXPECT_EQ(*map.log_odds(map::VoxelKey{x, 0, 0}), map.miss_log_odds()) << "one observation only";
    }
    EXPECT_EQ(map.state(map::VoxelKey{10, 0, 0}), map::VoxelState::kOccupied);
    EXPECT_EQ(*map.log_odds(map::VoxelKey{10, 0, 0}), map.hit_log_odds());
    EXPECT_EQ(map.state(map::VoxelKey{11, 0, 0}), map::VoxelState::kUnknown);
    EXPECT_EQ(map.state(map::VoxelKey{-1, 0, 0}), map::VoxelState::kUnknown);
    EXPECT_EQ(map.state(map::VoxelKey{5, 1, 0}), map::VoxelState::kUnknown);
    EXPECT_EQ(map.grid().free_voxels(), 10);
    EXPECT_EQ(map.grid().occupied_voxels(), 1);
    EXPECT_EQ(res.report.hits, 1);
    EXPECT_EQ(res.delta.changes.size(), 11u);
    EXPECT_EQ(res.delta.seq, 1);
  }
}

TEST(Integration, RayBeyondMaxRangeClearsUpToTheRangeWithoutAnObstacle) {
  SingleRay r;
  const FrameResult res = r.shoot(7000);  // camera max_range is 5 m
  EXPECT_EQ(res.report.beyond_range, 1);
  EXPECT_EQ(res.report.hits, 0);
  const OccupancyMap& map = r.mapper.map();
  // The max-range point x = 5.05 lies in voxel 50, which is not observed (OctoMap's convention).
  for (int x = 0; x < 50; ++x)
    EXPECT_EQ(map.state(map::VoxelKey{x, 0, 0}), map::VoxelState::kFree) << "x=" << x;
  EXPECT_EQ(map.state(map::VoxelKey{50, 0, 0}), map::VoxelState::kUnknown);
  EXPECT_EQ(map.state(map::VoxelKey{70, 0, 0}), map::VoxelState::kUnknown);
  EXPECT_EQ(map.grid().occupied_voxels(), 0);
}

TEST(Integration, NoReturnPixelsClearFreeSpaceUpToMaxRange) {
  SingleRay r;
  const FrameResult res = r.shoot(runtime::kDepthNoReturn);
  EXPECT_EQ(res.report.no_return, 1);
  EXPECT_EQ(r.mapper.map().grid().free_voxels(), 50);
  EXPECT_EQ(r.mapper.map().grid().occupied_voxels(), 0);
  EXPECT_EQ(r.mapper.map().state(map::VoxelKey{49, 0, 0}), map::VoxelState::kFree);
  EXPECT_EQ(r.mapper.map().state(map::VoxelKey{50, 0, 0}), map::VoxelState::kUnknown);
}

TEST(Integration, MapperMaxRangeTightensTheCameras) {
  MapperConfig cfg;
  cfg.integration.max_range = 2.0;
  Mapper mapper(cfg);
  const std::vector<uint16_t> depth{3000};
  const FrameResult res =
      mapper.integrate(DepthFrame::view(axis_camera(), looking_along_x({0.05, 0.05, 0.05}), depth));
  EXPECT_EQ(res.report.beyond_range, 1);
  EXPECT_EQ(mapper.map().grid().free_voxels(), 20);
  EXPECT_EQ(mapper.map().state(map::VoxelKey{20, 0, 0}), map::VoxelState::kUnknown);
}

TEST(Integration, InvalidDepthValuesAreIgnoredAndCounted) {
  Mapper mapper{MapperConfig{}};
  const runtime::PinholeCamera cam = axis_camera(6, 1, 1000.0);
  // zero, too near (0.1 m < 0.5 m), no return, huge (65.534 m), valid, valid at exactly min range
  const std::vector<uint16_t> depth{0, 100, runtime::kDepthNoReturn, runtime::kDepthMaxEncodable, 2000, 500};
  const FrameResult res = mapper.integrate(DepthFrame::view(cam, looking_along_x({0.05, 0.05, 0.05}), depth));
  ASSERT_TRUE(res.report.accepted);
  EXPECT_EQ(res.report.pixels, 6);
  EXPECT_EQ(res.report.invalid, 1);
  EXPECT_EQ(res.report.too_near, 1);
  EXPECT_EQ(res.report.no_return, 1);
  EXPECT_EQ(res.report.beyond_range, 1);
  EXPECT_EQ(res.report.hits, 2);
  EXPECT_EQ(mapper.totals().invalid, 1);
  // All rays run (nearly) along +x: the 2 m return is the only obstacle beyond the 0.5 m one...
  // which "hit wins" keeps occupied although the longer rays cross it.
  EXPECT_EQ(mapper.map().state(map::VoxelKey{5, 0, 0}), map::VoxelState::kOccupied);
  EXPECT_EQ(mapper.map().state(map::VoxelKey{20, 0, 0}), map::VoxelState::kOccupied);
  EXPECT_EQ(*mapper.map().log_odds(map::VoxelKey{5, 0, 0}), mapper.map().hit_log_odds());
  EXPECT_EQ(mapper.map().state(map::VoxelKey{30, 0, 0}), map::VoxelState::kFree);  // cleared by the far rays
}

TEST(Integration, EachVoxelGetsOneObservationPerFrameAndHitsWin) {
  for (auto mode : kAllModes) {
    Mapper mapper(test::config_with_mode(mode));
    // Two rays a micro-radian apart: the 2 m one crosses the 1 m one's end voxel.
    runtime::PinholeCamera cam = axis_camera(2, 1, 1.0e6);
    cam.cx = 0.5;
    const std::vector<uint16_t> depth{1000, 2000};
    mapper.integrate(DepthFrame::view(cam, looking_along_x({0.05, 0.05, 0.05}), depth));
    const OccupancyMap& map = mapper.map();
    EXPECT_EQ(*map.log_odds(map::VoxelKey{10, 0, 0}), map.hit_log_odds());
    EXPECT_EQ(*map.log_odds(map::VoxelKey{20, 0, 0}), map.hit_log_odds());
    for (int x : {0, 3, 9, 11, 19})
      EXPECT_EQ(*map.log_odds(map::VoxelKey{x, 0, 0}), map.miss_log_odds()) << x;
  }
}

TEST(Integration, AReturnWinsOverAMaxRangeRayEndingInTheSameVoxel) {
  for (auto mode : kAllModes) {
    Mapper mapper(test::config_with_mode(mode));
    runtime::PinholeCamera cam = axis_camera(2, 1, 1.0e6);
    cam.cx = 0.5;
    // The first ray is clipped at 5 m (its end voxel is not observed); the second returns at
    // exactly 5 m, in the same voxel, which must become occupied.
    const std::vector<uint16_t> depth{7000, 5000};
    mapper.integrate(DepthFrame::view(cam, looking_along_x({0.05, 0.05, 0.05}), depth));
    EXPECT_EQ(mapper.map().state(map::VoxelKey{50, 0, 0}), map::VoxelState::kOccupied) << to_string(mode);
    EXPECT_EQ(mapper.map().state(map::VoxelKey{49, 0, 0}), map::VoxelState::kFree);
  }
}

// SingleRay with OctoMap's rule everywhere (no hold range).
struct OctomapRay : SingleRay {
  OctomapRay() {
    config.occupancy.hold_range = 0.0;
    mapper = Mapper(config);
  }
};

TEST(Integration, LogOddsAreClampedSoTheMapCanChangeItsMind) {
  OctomapRay r;
  for (int i = 0; i < 40; ++i) r.shoot(1000);
  const OccupancyMap& map = r.mapper.map();
  EXPECT_FLOAT_EQ(*map.log_odds(map::VoxelKey{10, 0, 0}), std::log(0.971 / (1 - 0.971)));
  EXPECT_FLOAT_EQ(*map.log_odds(map::VoxelKey{3, 0, 0}), std::log(0.1192 / (1 - 0.1192)));
  EXPECT_EQ(*map.log_odds(map::VoxelKey{10, 0, 0}), map.max_log_odds());
  EXPECT_EQ(*map.log_odds(map::VoxelKey{3, 0, 0}), map.min_log_odds());
  // The obstacle moves 1 m further: the clamped voxel turns free after a bounded number of frames
  // (OctoMap's point of clamping): logit(0.971) = 3.51 over misses of 0.405 -> 9 frames.
  int frames = 0;
  while (map.state(map::VoxelKey{10, 0, 0}) == map::VoxelState::kOccupied && frames < 100) {
    r.shoot(2000);
    ++frames;
  }
  EXPECT_EQ(frames, 9);
}

// The end of a thin door leaf: hit from close by until certain, then passed through by the rays of
// another view. It stays occupied however long the other view lasts.
TEST(Integration, AVoxelCertainFromCloseHitsIsHeldAgainstLaterMisses) {
  SingleRay r;
  ASSERT_EQ(r.config.occupancy.hold_range, 2.0);
  const OccupancyMap& map = r.mapper.map();
  const map::VoxelKey end{10, 0, 0};  // 1 m away
  for (int i = 0; i < 4; ++i) r.shoot(1000);
  EXPECT_LT(*map.log_odds(end), map.max_log_odds()) << "not certain yet: not held";
  r.shoot(1000);
  EXPECT_TRUE(map.is_held(end));
  for (int i = 0; i < 100; ++i) r.shoot(2000);
  EXPECT_EQ(map.state(end), map::VoxelState::kOccupied);
  EXPECT_TRUE(map.is_held(end));
  EXPECT_EQ(map.state(map::VoxelKey{20, 0, 0}), map::VoxelState::kOccupied) << "the new end is mapped";
  EXPECT_EQ(map.state(map::VoxelKey{15, 0, 0}), map::VoxelState::kFree);

  // A checkpoint keeps it held; the OctoMap export writes it as its most certain value.
  const std::string path = test::temp_path("held.map");
  r.mapper.save_checkpoint(path, 1);
  Mapper back{r.config};
  back.load_checkpoint(path);
  EXPECT_TRUE(back.map().is_held(end));
  back.integrate(DepthFrame::view(r.cam, looking_along_x({0.05, 0.05, 0.05}), r.depth));
  EXPECT_EQ(back.map().state(end), map::VoxelState::kOccupied);
  MapperConfig octomap_rule = r.config;
  octomap_rule.occupancy.hold_range = 0.0;
  Mapper plain{octomap_rule};
  plain.load_checkpoint(path);
  EXPECT_EQ(*plain.map().log_odds(end), plain.map().max_log_odds()) << "no holding: clamped";
  std::remove(path.c_str());
  const std::unique_ptr<octomap::OcTree> tree = to_octree(map);
  const octomap::OcTreeNode* node = tree->search(1.05, 0.05, 0.05);
  ASSERT_NE(node, nullptr);
  EXPECT_FLOAT_EQ(node->getLogOdds(), map.max_log_odds());
}

// Far hits do not hold (depth noise grows with range, and a doorway's edge seen from afar must
// clear when seen up close): a voxel certain from 3 m away clears as OctoMap's would.
TEST(Integration, AVoxelCertainOnlyFromFarHitsStillChangesItsMind) {
  SingleRay r;
  const OccupancyMap& map = r.mapper.map();
  const map::VoxelKey end{30, 0, 0};  // 3 m away, beyond hold_range
  for (int i = 0; i < 40; ++i) r.shoot(3000);
  EXPECT_EQ(*map.log_odds(end), map.max_log_odds());
  EXPECT_FALSE(map.is_held(end));
  int frames = 0;
  while (map.state(end) == map::VoxelState::kOccupied && frames < 100) {
    r.shoot(4000);
    ++frames;
  }
  EXPECT_EQ(frames, 9);
}

TEST(Integration, RejectsUnusableFramesAndCountsThem) {
  Mapper mapper{MapperConfig{}};
  const runtime::PinholeCamera cam = axis_camera();
  const std::vector<uint16_t> depth{1000};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  Eigen::Isometry3d nan_pose = looking_along_x({0, 0, 0});
  nan_pose.translation().x() = nan;
  Eigen::Isometry3d inf_pose = looking_along_x({0, 0, 0});
  inf_pose.linear()(1, 1) = inf;
  Eigen::Isometry3d far_pose = looking_along_x({1e30, 0, 0});
  Eigen::Isometry3d scaled = looking_along_x({0, 0, 0});
  scaled.linear() *= 2.0;
  runtime::PinholeCamera bad_f = cam;
  bad_f.fx = 0.0;
  runtime::PinholeCamera nan_c = cam;
  nan_c.cy = nan;
  runtime::PinholeCamera fisheye = axis_camera(640, 480, 1.0);  // +-320 m wide at 5 m depth

  struct Case {
    DepthFrame frame;
    const char* expect;
  };
  std::vector<uint16_t> short_depth;
  const std::vector<uint16_t> wide_depth(640 * 480, 1000);
  const Case cases[] = {
      {DepthFrame::view(cam, nan_pose, depth), "pose is not finite"},
      {DepthFrame::view(cam, inf_pose, depth), "pose is not finite"},
      {DepthFrame::view(cam, far_pose, depth), "beyond"},
      {DepthFrame::view(cam, scaled, depth), "not a rotation"},
      {DepthFrame::view(bad_f, looking_along_x({0, 0, 0}), depth), "intrinsics"},
      {DepthFrame::view(nan_c, looking_along_x({0, 0, 0}), depth), "intrinsics"},
      {DepthFrame::view(cam, looking_along_x({0, 0, 0}), short_depth), "expected 1"},
      {DepthFrame::view(fisheye, looking_along_x({0, 0, 0}), wide_depth), "too wide"},
  };
  for (const Case& c : cases) {
    const FrameResult res = mapper.integrate(c.frame);
    EXPECT_FALSE(res.report.accepted);
    EXPECT_NE(res.report.error.find(c.expect), std::string::npos) << res.report.error;
  }
  EXPECT_EQ(mapper.frames_rejected(), 8);
  EXPECT_EQ(mapper.frames_integrated(), 0);
  EXPECT_EQ(mapper.seq(), 0);
  EXPECT_EQ(mapper.map().grid().num_blocks(), 0u);
}

TEST(Integration, MapGrowsToWhereverTheCameraLooks) {
  Mapper mapper{MapperConfig{}};
  const runtime::PinholeCamera cam = test::small_camera();
  // The same room placed around the origin and far away at negative coordinates.
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-1234.5, 876.0, -40.0)}) {
    const SyntheticRoom room({offset, offset + Eigen::Vector3d(6, 5, 2.7)}, {});
    const Eigen::Isometry3d pose = camera_pose(offset + Eigen::Vector3d(3, 2.5, 1.3), 0.3);
    const std::vector<uint16_t> depth = room.render(cam, pose);
    ASSERT_TRUE(mapper.integrate(DepthFrame::view(cam, pose, depth)).report.accepted);
    // The far wall (x = offset + 6) is seen straight ahead.
    const Eigen::Vector3d ahead = pose * Eigen::Vector3d(0, 0, 1);
    const Eigen::Vector3d dir = (ahead - pose.translation()).normalized();
    const double t = room.cast(pose.translation(), dir);
    // The return lands within a millimetre of the wall, on either side of the voxel boundary.
    const bool wall = mapper.map().state(Eigen::Vector3d(pose.translation() + dir * (t + 0.01))) ==
                          map::VoxelState::kOccupied ||
                      mapper.map().state(Eigen::Vector3d(pose.translation() + dir * (t - 0.01))) ==
                          map::VoxelState::kOccupied;
    EXPECT_TRUE(wall);
    EXPECT_EQ(mapper.map().state(Eigen::Vector3d(pose.translation() + dir * (t * 0.5))),
              map::VoxelState::kFree);
  }
  const map::MapStats s = mapper.stats(false);
  EXPECT_LT(s.bounds_min.x(), -1230.0);
  EXPECT_GT(s.bounds_max.x(), 5.0);
}

TEST(Integration, ConfiguredBoundsLimitTheMap) {
  MapperConfig cfg;
  cfg.occupancy.bounds_min = {-1.0, -1.0, -1.0};
  cfg.occupancy.bounds_max = {0.5, 1.0, 1.0};
  Mapper mapper(cfg);
  const std::vector<uint16_t> depth{1000};
  const FrameResult res =
      mapper.integrate(DepthFrame::view(axis_camera(), looking_along_x({0.05, 0.05, 0.05}), depth));
  // Voxels 0..4 have centres below 0.5 m; 5..10 are outside and never updated.
  EXPECT_EQ(mapper.map().grid().free_voxels(), 5);
  EXPECT_EQ(mapper.map().grid().occupied_voxels(), 0);
  EXPECT_EQ(res.report.out_of_bounds, 6);
  EXPECT_EQ(mapper.map().state(map::VoxelKey{10, 0, 0}), map::VoxelState::kUnknown);
}

TEST(Integration, PixelStepSkipsPixels) {
  MapperConfig cfg;
  cfg.integration.pixel_step = 4;
  Mapper mapper(cfg);
  const runtime::PinholeCamera cam = test::small_camera();
  const auto frames = test::room_frames(1, cam);
  const FrameResult res = mapper.integrate(DepthFrame::view(cam, frames[0].pose, frames[0].depth));
  EXPECT_EQ(res.report.pixels, (160 / 4) * (120 / 4));
  EXPECT_GT(mapper.map().grid().free_voxels(), 1000);
}

// The reference: OctoMap's insertPointCloud on the same frames.
TEST(Integration, AgreesWithOctomapOnTheSameFrames) {
  const runtime::PinholeCamera cam = test::small_camera();
  const auto frames = test::room_frames(6, cam, 6);
  octomap::OcTree tree(0.1);
  for (const auto& f : frames) test::octomap_insert(tree, cam, f);
  struct Expect {
    IntegrationParams::Mode mode;
    double min_agreement;
  };
  // Exact mode walks OctoMap's rays and differs only by floating-point ties.
  for (const Expect e :
       {Expect{IntegrationParams::Mode::kExact, 0.999}, Expect{IntegrationParams::Mode::kBundled, 0.995}}) {
    Mapper mapper(test::config_with_mode(e.mode));
    for (const auto& f : frames) mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
    octomap::OcTree copy(tree);
    const double a = test::agreement(mapper.map().grid(), copy);
    EXPECT_GE(a, e.min_agreement) << to_string(e.mode);
  }
}

TEST(Integration, FreeAndOccupiedMatchTheRoomsGeometry) {
  // Every voxel the map calls occupied touches a surface of the room; free voxels are in the
  // open (a millimetre of depth rounding at a corner may free a voxel whose centre is just
  // inside a wall, hence a tolerance).
  const runtime::PinholeCamera cam = test::small_camera();
  const SyntheticRoom room = SyntheticRoom::furnished();
  Mapper mapper{MapperConfig{}};
  for (const auto& f : test::room_frames(12, cam, 12))
    mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
  int64_t occupied = 0, free = 0, free_in_solid = 0;
  const double h = 0.05 + 1e-3;
  mapper.map().grid().for_each_block([&](const map::VoxelKey& bk, const map::VoxelBlock& b) {
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (b.state[i] == map::VoxelState::kUnknown) continue;
      const Eigen::Vector3d c = mapper.map().keys().center(map::voxel_of(bk, i));
      bool touches_solid = false, inside_solid = room.solid(c);
      for (int dx = -1; dx <= 1; dx += 2)
        for (int dy = -1; dy <= 1; dy += 2)
          for (int dz = -1; dz <= 1; dz += 2)
            touches_solid |= room.solid(c + Eigen::Vector3d(dx, dy, dz) * h);
      if (b.state[i] == map::VoxelState::kOccupied) {
        ++occupied;
        EXPECT_TRUE(touches_solid) << c.transpose();
      } else {
        ++free;
        free_in_solid += inside_solid;
      }
    }
  });
  EXPECT_GT(occupied, 3000);
  EXPECT_GT(free, 30000);
  EXPECT_LE(free_in_solid, free / 1000);
}

}  // namespace
}  // namespace semx::mapper
