// Stage 2: back-projection against known geometry (boxes rendered by the simulator's rasteriser
// at known poses), and the PCL filtering: voxel grid, outliers, largest cluster.
#include <gtest/gtest.h>

#include "semantics_test_util.hpp"
#include "semx/semantics/detector.hpp"
#include "semx/semantics/lifter.hpp"

using namespace semx::semantics;
using namespace semx::semantics::test;

namespace {

// Distance from p to the surface of an axis-aligned box (0 on it, positive off it either way).
double surface_distance(const Eigen::AlignedBox3d& b, const Eigen::Vector3d& p) {
  if (!b.contains(p)) return b.exteriorDistance(p);
  const Eigen::Vector3d in = (p - b.min()).cwiseMin(b.max() - p);
  return in.minCoeff();
}

const Detection2D* find(const std::vector<Detection2D>& ds, SemanticClass c) {
  for (const auto& d : ds) {
    if (d.cls == c) return &d;
  }
  return nullptr;
}

}  // namespace

TEST(Lifter, BackProjectedPixelsLieOnTheRenderedBox) {
  const Eigen::Vector3d centre(3.5, 2.0, 0.45), size(0.6, 1.0, 0.9);
  Scene scene(room({Solid::box(SemanticClass::kCabinet, centre, size)}));
  const Eigen::AlignedBox3d truth(centre - size / 2, centre + size / 2);
  // Several viewpoints: head-on, from the side, diagonal and close.
  const Eigen::Vector3d views[] = {{1.0, 2.0, 1.4}, {3.5, 0.3, 1.2}, {1.5, 4.0, 1.6}, {2.4, 1.2, 1.0}};
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  for (const auto& eye : views) {
    SCOPED_TRACE(::testing::Message() << "eye " << eye.transpose());
    const Frame f = scene.render(eye, look_at(eye, centre));
    const auto ds = det.detect(f);
    const Detection2D* d = find(ds, SemanticClass::kCabinet);
    ASSERT_NE(d, nullptr);
    const auto pts = ObjectLifter::back_project(f, *d, 1);
    ASSERT_GT(pts.size(), 500u);
    double worst = 0;
    for (const auto& p : pts) worst = std::max(worst, surface_distance(truth, p.cast<double>()));
    // Depth is quantised to 1 mm and the rasteriser is exact: every point is on the surface.
    EXPECT_LT(worst, 0.005);
  }
}

TEST(Lifter, CentroidAndExtentOfTheVisiblePart) {
  // A box seen head-on from -x: the visible part is its -x face and its top (camera above).
  const Eigen::Vector3d centre(3.5, 2.0, 0.45), size(0.6, 1.0, 0.9);
  Scene scene(room({Solid::box(SemanticClass::kCabinet, centre, size)}));
  const Frame f = scene.render({1.0, 2.0, 1.4}, 0.0);
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  ObjectLifter lifter(LiftConfig{});
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  LiftOutcome outcome;
  const auto d3 = lifter.lift(f, ds[0], &outcome);
  ASSERT_TRUE(d3.has_value());
  EXPECT_EQ(outcome, LiftOutcome::kOk);
  EXPECT_EQ(d3->cls, SemanticClass::kCabinet);
  const double v = LiftConfig{}.voxel_size;
  // y and z span the whole box (within a voxel: points are voxel centroids); x covers the front
  // face and the top, which ends at the back edge.
  EXPECT_NEAR(d3->box.min().y(), 1.5, v);
  EXPECT_NEAR(d3->box.max().y(), 2.5, v);
  EXPECT_NEAR(d3->box.min().z(), 0.0, v);
  EXPECT_NEAR(d3->box.max().z(), 0.9, v);
  EXPECT_NEAR(d3->box.min().x(), 3.2, v);
  EXPECT_NEAR(d3->box.max().x(), 3.8, v);
  EXPECT_NEAR(d3->centroid.y(), 2.0, 0.05);
  // The voxel grid keeps one point per voxel.
  EXPECT_LT(d3->points.size(), static_cast<std::size_t>(d3->depth_pixels));
}

TEST(Lifter, YawedCameraAndYawedBox) {
  const Eigen::Vector3d centre(3.0, 2.5, 0.4);
  Solid s = Solid::box(SemanticClass::kBed, centre, {1.0, 1.8, 0.8}, 35 * M_PI / 180);
  Scene scene(room({s}));
  const Eigen::AlignedBox3d truth(s.bounds().min, s.bounds().max);
  const Eigen::Vector3d eye(0.8, 0.7, 1.5);
  const Frame f = scene.render(eye, look_at(eye, centre) + 0.2);
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  ObjectLifter lifter(LiftConfig{});
  const auto d3 = lifter.lift(f, ds[0]);
  ASSERT_TRUE(d3.has_value());
  // Every point inside the yawed box's axis-aligned bounds (within rounding and a voxel).
  for (const auto& p : d3->points)
    EXPECT_TRUE(truth.exteriorDistance(p.cast<double>()) < 0.01) << p.transpose();
  EXPECT_TRUE(truth.contains(d3->centroid));
}

TEST(Lifter, StrideFollowsDepth) {
  ObjectLifter lifter(LiftConfig{});
  const semx::runtime::PinholeCamera cam;
  EXPECT_EQ(lifter.stride_for_depth(cam, 0.5), LiftConfig{}.max_pixel_stride);
  EXPECT_GT(lifter.stride_for_depth(cam, 1.0), lifter.stride_for_depth(cam, 4.0));
  EXPECT_GE(lifter.stride_for_depth(cam, 5.0), 1);
  EXPECT_EQ(lifter.stride_for_depth(cam, 1000.0), 1);
}

TEST(Lifter, InvalidAndNoReturnPixelsAreSkipped) {
  Frame f = blank_frame();
  paint(f, 200, 200, 100, 100, SemanticClass::kChair, 1, 2000);
  // Half the mask without a measurement, a quarter beyond range.
  for (int v = 200; v < 300; ++v) {
    for (int u = 200; u < 250; ++u)
      f.depth[static_cast<std::size_t>(v) * 640 + u] = semx::runtime::kDepthInvalid;
    for (int u = 250; u < 275; ++u)
      f.depth[static_cast<std::size_t>(v) * 640 + u] = semx::runtime::kDepthNoReturn;
  }
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  const auto pts = ObjectLifter::back_project(f, ds[0], 1);
  EXPECT_EQ(pts.size(), 25u * 100u);
  for (const auto& p : pts) EXPECT_NEAR(p.x(), 2.0, 1e-6);  // optical z is world x here
  // Nothing measurable at all: no 3D detection, and why.
  for (auto& d : f.depth) d = semx::runtime::kDepthInvalid;
  ObjectLifter lifter(LiftConfig{});
  LiftOutcome outcome;
  EXPECT_FALSE(lifter.lift(f, ds[0], &outcome).has_value());
  EXPECT_EQ(outcome, LiftOutcome::kNoDepth);
}

TEST(Clustering, TheLargestClusterIsTheObjectAndStrayPointsGo) {
  // A chair mask at 2 m whose edge bleeds onto the wall 2 m behind it, plus isolated stray depths.
  Frame f = blank_frame();
  paint(f, 200, 150, 120, 160, SemanticClass::kChair, 1, 2000);
  for (int v = 150; v < 310; ++v) {
    for (int u = 316; u < 320; ++u) f.depth[static_cast<std::size_t>(v) * 640 + u] = 4000;
  }
  for (int k = 0; k < 6; ++k)
    f.depth[static_cast<std::size_t>(160 + 20 * k) * 640 + 210 + 15 * k] = 3000 + 100 * k;
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  LiftConfig lc;
  lc.max_pixel_stride = 1;  // every pixel, so the stray ones are certainly sampled
  ObjectLifter lifter(lc);
  const auto d3 = lifter.lift(f, ds[0]);
  ASSERT_TRUE(d3.has_value());
  // Only the 2 m plane survives.
  EXPECT_NEAR(d3->box.min().x(), 2.0, 1e-3);
  EXPECT_NEAR(d3->box.max().x(), 2.0, 1e-3);
  EXPECT_NEAR(d3->centroid.x(), 2.0, 1e-3);
}

TEST(Clustering, TwoSeparateSurfacesKeepTheBiggerOne) {
  Frame f = blank_frame();
  paint(f, 100, 100, 200, 200, SemanticClass::kSofa, 1, 2000);  // big, near
  paint(f, 400, 100, 60, 60, SemanticClass::kSofa, 1, 2000);    // small, 1.5 m to the side
  LabelDetector det(DetectorConfig{}, RegionConfig{});
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);  // one instance: one mask of two parts
  ObjectLifter lifter(LiftConfig{});
  const auto d3 = lifter.lift(f, ds[0]);
  ASSERT_TRUE(d3.has_value());
  // Optical x (image right) is world -y: the big part spans u 100..299, i.e. y in [0.13, 1.38].
  EXPECT_GT(d3->box.min().y(), -0.5);
  EXPECT_LT(d3->box.max().y(), 1.5);
  EXPECT_GT(d3->box.sizes().y(), 1.0);
}
