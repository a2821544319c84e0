// The coverage plot (ticks, threshold line, curves) and the top-down map picture (column classes,
// ground-truth underlay, overlays), checked on their pixels.
#include <gtest/gtest.h>

#include <filesystem>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/coverage_plot.hpp"
#include "semx/evaluator/map_picture.hpp"

namespace semx::evaluator {
namespace {

int count_pixels(const Image& img, Rgb c, int tolerance = 0) {
  int n = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const Rgb p = img.at(x, y);
      if (std::abs(p.r - c.r) <= tolerance && std::abs(p.g - c.g) <= tolerance &&
          std::abs(p.b - c.b) <= tolerance)
        ++n;
    }
  }
  return n;
}

TEST(CoveragePlot, NiceTicks) {
  auto t = nice_ticks(100, 10);
  ASSERT_EQ(t.size(), 11u);
  EXPECT_DOUBLE_EQ(t[1], 10);
  EXPECT_DOUBLE_EQ(t.back(), 100);
  t = nice_ticks(437, 8);
  EXPECT_DOUBLE_EQ(t[1], 100);  // 437/8 = 54.6 -> 100
  t = nice_ticks(3.2, 8);
  EXPECT_DOUBLE_EQ(t[1], 0.5);
  EXPECT_DOUBLE_EQ(nice_ticks(0).back(), 1.0);  // degenerate: 0..1
}

TEST(CoveragePlot, DrawsTheCurvesAndThe85PercentLine) {
  PlotSeries a = coverage_series({{0, 0, 0, 0}, {50, 60, 0, 0}, {100, 92, 0, 0}}, "semantic-dep");
  PlotSeries b;
  b.label = "dep";
  b.points = {{0, 0}, {100, 70}};
  a.color = {200, 30, 30};
  b.color = {30, 160, 30};
  CoveragePlotOptions o;
  const Image img = render_coverage_plot({a, b}, o);
  EXPECT_EQ(img.width, o.width);
  EXPECT_EQ(img.height, o.height);
  EXPECT_GT(count_pixels(img, a.color), 200);
  EXPECT_GT(count_pixels(img, b.color), 200);
  // The dashed threshold line: reddish (BGR 40,40,200 -> RGB 200,40,40) pixels on one row.
  EXPECT_GT(count_pixels(img, {200, 40, 40}, 20), 150);
  const std::string dir = test::temp_dir("plot");
  std::filesystem::create_directories(dir);
  write_coverage_plot(dir + "/c.png", {a, b});
  EXPECT_GT(std::filesystem::file_size(dir + "/c.png"), 1000u);
}

TEST(MapPicture, ColumnsOverlaysAndTheGroundTruthUnderlay) {
  const simulator::World world = test::small_world();
  const simulator::GroundTruth gt(world, 0.1);
  map::StateGrid grid(0.1);
  // A free column at x = 1.05, y = 1.25 and an occupied voxel above a free one at x = 2.05.
  for (int z = 2; z < 15; ++z) grid.set_state({10, 12, z}, map::VoxelState::kFree);
  grid.set_state({20, 12, 5}, map::VoxelState::kFree);
  grid.set_state({20, 12, 6}, map::VoxelState::kOccupied);
  // Outside the projected heights (the floor slab): not drawn.
  grid.set_state({5, 5, -1}, map::VoxelState::kOccupied);

  MapPictureOptions o;
  o.max_side_px = 340;  // 34 columns -> 10 px per column
  MapPicture pic(grid, MapView::of_world(world), o);
  EXPECT_EQ(pic.columns_x(), 34);
  EXPECT_EQ(pic.columns_y(), 29);
  EXPECT_EQ(pic.pixels_per_column(), 10);
  // Column (ix, iy) of key (kx, ky): kx - floor(-0.2 / 0.1) = kx + 2.
  EXPECT_EQ(pic.column(12, 14), MapPicture::Column::kFree);
  EXPECT_EQ(pic.column(22, 14), MapPicture::Column::kOccupied);
  EXPECT_EQ(pic.column(7, 7), MapPicture::Column::kUnknown);
  EXPECT_EQ(pic.count(MapPicture::Column::kFree), 1);
  EXPECT_EQ(pic.count(MapPicture::Column::kOccupied), 1);

  pic.underlay_ground_truth(gt);
  EXPECT_EQ(pic.column(0, 10), MapPicture::Column::kUnmappedWall);  // the west wall
  EXPECT_EQ(pic.column(7, 7), MapPicture::Column::kUnknown);        // open floor
  EXPECT_EQ(pic.column(12, 14), MapPicture::Column::kFree);

  const Rgb blue{10, 20, 250}, orange{250, 140, 0};
  pic.add_polyline(std::vector<Eigen::Vector2d>{{0.5, 0.5}, {2.5, 0.5}}, blue, 3);
  pic.add_circle({1.5, 1.8}, 0.4, orange, "chair 0.7", true);
  pic.add_marker({0.5, 0.5}, {0, 200, 0}, "start");
  const Image img = pic.render();
  // The free column's pixels are the free colour; the polyline is drawn at y = 0.5 m.
  const Eigen::Vector2i fp = pic.pixel({1.05, 1.25});
  EXPECT_EQ(img.at(fp.x(), fp.y()), o.free);
  const Eigen::Vector2i op = pic.pixel({2.05, 1.25});
  EXPECT_EQ(img.at(op.x(), op.y()), o.occupied);
  const Eigen::Vector2i lp = pic.pixel({1.5, 0.5});
  EXPECT_EQ(img.at(lp.x(), lp.y()), blue);
  EXPECT_GT(count_pixels(img, orange), 50);
  // y up: a point further north is higher in the picture.
  EXPECT_LT(pic.pixel({1, 2}).y(), pic.pixel({1, 1}).y());

  const std::string dir = test::temp_dir("map");
  std::filesystem::create_directories(dir);
  pic.write_png(dir + "/map.png");
  EXPECT_GT(std::filesystem::file_size(dir + "/map.png"), 1000u);
}

TEST(MapPicture, RunPictureDrawsTheTrajectory) {
  const simulator::World world = test::small_world();
  const simulator::GroundTruth gt(world, 0.1);
  map::StateGrid grid(0.1);
  const std::vector<Eigen::Vector3d> traj = {{0.5, 0.5, 1}, {1.5, 0.6, 1}, {2.5, 2.0, 1}};
  MapPicture pic = run_map_picture(grid, world, &gt, traj, "small");
  const Image img = pic.render();
  EXPECT_GT(count_pixels(img, {30, 90, 220}), 30);  // the trajectory's colour
  EXPECT_GT(pic.count(MapPicture::Column::kUnmappedWall), 100);
}

}  // namespace
}  // namespace semx::evaluator
