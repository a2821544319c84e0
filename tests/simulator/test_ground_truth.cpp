#include <gtest/gtest.h>

#include <map>

#include "semx/simulator/ground_truth.hpp"
#include "test_util.hpp"

namespace semx::simulator {
namespace {

TEST(GroundTruth, ExactCountsInABoxRoom) {
  // Interior 2 x 2 x 2 m on the 0.1 m grid: 20³ free voxels, each face of the shell 20² voxels.
  World w = test::box_room(2, 2, 2);
  w.start.position = {0.55, 0.55, 1.05};
  const GroundTruth empty(w, 0.1);
  EXPECT_EQ(empty.reachable_free_count(), 8000u);
  EXPECT_EQ(empty.occupied_in_target_count(), 2400u);
  EXPECT_EQ(empty.target_count(), 10400u);
  EXPECT_NEAR(empty.reachable_area(), 4.0, 1e-9);
  // A 0.4 m cube on the floor: 64 voxels fewer free; its voxels on the 5 exposed faces
  // (64 less the 2 x 2 x 3 inner ones = 52) join T; the 16 floor voxels under it leave T.
  w.solids.push_back(Solid::box(SemanticClass::kCabinet, {1.2, 1.2, 0.2}, {0.4, 0.4, 0.4}));
  const GroundTruth gt(w, 0.1);
  EXPECT_EQ(gt.reachable_free_count(), 8000u - 64u);
  EXPECT_EQ(gt.occupied_in_target_count(), 2400u + 52u - 16u);
  EXPECT_EQ(gt.cell(gt.key_of({1.25, 1.25, 0.15})), GroundTruth::kOccupied);
  EXPECT_TRUE(gt.in_target(gt.key_of({1.05, 1.25, 0.35})));    // a face voxel
  EXPECT_FALSE(gt.in_target(gt.key_of({1.25, 1.25, 0.15})));   // inside the cube
  EXPECT_FALSE(gt.in_target(gt.key_of({0.55, 0.55, -0.15})));  // deep in the floor slab
  ASSERT_EQ(gt.objects().size(), 1u);
  EXPECT_EQ(gt.objects()[0].cls, SemanticClass::kCabinet);
  EXPECT_TRUE(gt.objects()[0].center.isApprox(Eigen::Vector3d(1.2, 1.2, 0.2)));
  EXPECT_TRUE(gt.objects()[0].extent.isApprox(Eigen::Vector3d(0.4, 0.4, 0.4)));
}

TEST(GroundTruth, SealedSpaceIsNotReachable) {
  // A closed 0.6 m box inside the room has free air inside that no path reaches.
  World w = test::box_room(3, 3, 2);
  w.start.position = {0.5, 0.5, 1.0};
  const auto add = [&](Eigen::Vector3d c, Eigen::Vector3d s) {
    w.solids.push_back(Solid::box(SemanticClass::kCabinet, c, s));
  };
  add({2.0, 2.0, 0.05}, {0.6, 0.6, 0.1});
  add({2.0, 2.0, 0.75}, {0.6, 0.6, 0.1});
  add({1.75, 2.0, 0.4}, {0.1, 0.6, 0.6});
  add({2.25, 2.0, 0.4}, {0.1, 0.6, 0.6});
  add({2.0, 1.75, 0.4}, {0.4, 0.1, 0.6});
  add({2.0, 2.25, 0.4}, {0.4, 0.1, 0.6});
  const GroundTruth gt(w, 0.1);
  EXPECT_EQ(gt.cell(gt.key_of({2.05, 2.05, 0.45})), GroundTruth::kFree);  // sealed air
  EXPECT_EQ(gt.cell(gt.key_of({1.05, 1.05, 0.45})), GroundTruth::kReachable);
  EXPECT_EQ(gt.reachable_free_count(), 30u * 30 * 20 - 6u * 6 * 8);
}

TEST(GroundTruth, ShippedWorldSetSizesArePlausible) {
  struct Expect {
    const char* name;
    double area, height;
  };
  for (const Expect& e : {Expect{"env1", 50, 2.7}, Expect{"env2", 100, 2.8}, Expect{"env3", 200, 2.7}}) {
    SCOPED_TRACE(e.name);
    const World w = test::shipped(e.name);
    const GroundTruth gt(w, 0.1);
    const double volume_voxels = e.area * e.height / 1e-3;
    // Furniture and walls take a little of the air; nothing is sealed off or leaks out.
    EXPECT_GT(gt.reachable_free_count(), 0.85 * volume_voxels);
    EXPECT_LT(gt.reachable_free_count(), 1.0 * volume_voxels);
    // T's occupied shell: at least floor + ceiling, at most a few times the room surface.
    EXPECT_GT(gt.occupied_in_target_count(), 2 * e.area / 1e-2);
    EXPECT_LT(gt.occupied_in_target_count(), 6 * e.area / 1e-2);
    EXPECT_EQ(gt.target_count(), gt.reachable_free_count() + gt.occupied_in_target_count());
    EXPECT_GE(gt.objects().size(), 25u);
    // The vehicle (not just air) reaches most of the free space.
    const VehicleReachability vr(gt, w.start.position);
    EXPECT_GT(vr.count(), gt.reachable_free_count() / 2);
  }
}

TEST(GroundTruth, VehicleReachesEveryRoomOfEnv3) {
  const World w = test::shipped("env3");
  const GroundTruth gt(w, 0.1);
  const VehicleReachability vr(gt, w.start.position);
  // A point in the open part of each room, at flight height.
  const Eigen::Vector3d rooms[] = {{3.5, 2.5, 1.2}, {9.0, 4.5, 1.2}, {12.2, 3.5, 1.2},  {14.7, 3.0, 1.2},
                                   {2.5, 9.0, 1.2}, {7.5, 9.5, 1.2}, {13.0, 10.5, 1.2}, {15.0, 6.25, 1.2}};
  for (const auto& p : rooms) EXPECT_TRUE(vr.reachable(p)) << p.transpose();
  // env2's two rooms are joined only by the 1 m passage.
  const World w2 = test::shipped("env2");
  const GroundTruth gt2(w2, 0.1);
  EXPECT_TRUE(VehicleReachability(gt2, w2.start.position).reachable({14.0, 3.0, 1.5}));
  const World w1 = test::shipped("env1");
  const GroundTruth gt1(w1, 0.1);
  const VehicleReachability vr1(gt1, w1.start.position);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(6.5, 1.8, 1.2), Eigen::Vector3d(7.0, 5.0, 1.5),
                                   Eigen::Vector3d(1.5, 5.5, 1.5), Eigen::Vector3d(0.8, 1.2, 1.5)}) {
    EXPECT_TRUE(vr1.reachable(p)) << p.transpose();
  }
}

}  // namespace
}  // namespace semx::simulator
