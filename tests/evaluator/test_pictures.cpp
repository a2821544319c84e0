// The coverage plot (ticks, threshold line, curves) and the top-down map picture (column classes,
// ground-truth underlay, overlays), checked on their pixels.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include "evaluator_test_util.hpp"
#include "semx/evaluator/coverage_plot.hpp"
#include "semx/evaluator/map_picture.hpp"
#include "semx/evaluator/run_overlays.hpp"

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
  EXPECT_GT(count_pixels(img, kTrajectoryColour), 30);
  EXPECT_GT(pic.count(MapPicture::Column::kUnmappedWall), 100);
}

TEST(MapPicture, OverlaysAndLabelsStayInsideTheMapFrame) {
  map::StateGrid grid(0.1);
  grid.set_state({5, 5, 10}, map::VoxelState::kFree);
  MapPictureOptions o;
  o.max_side_px = 300;
  MapView v;
  v.lo = {0, 0};
  v.hi = {4, 3};
  const Image bare = MapPicture(grid, v, o).render();
  MapPicture pic(grid, v, o);
  const Rgb c{200, 0, 160};
  // A region far larger than the map, one whose centre lies outside it, a long label at the
  // corner, roadmap edges running off every side, a marker on the edge.
  pic.add_circle({2, 1.5}, 30, c, "a region larger than the map", true, 3);
  pic.add_circle({-0.5, 3.2}, 1.0, c, "outside", false, 2, 0.6);
  pic.add_segments({{{-5, -5}, {9, 8}}, {{-3, 1}, {9, 1}}}, {0, 0, 0}, 2, 0.5);
  pic.add_marker({4, 3}, {220, 30, 30}, "a marker label on the corner of the map", 6);
  pic.add_text({3.9, 0.1}, "text at the edge", c);
  const Image img = pic.render();
  ASSERT_EQ(img.width, bare.width);
  ASSERT_EQ(img.height, bare.height);
  const int m = o.margin_px, w = pic.columns_x() * pic.pixels_per_column(),
            h = pic.columns_y() * pic.pixels_per_column();
  int outside_changed = 0, inside_changed = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const bool inside = x >= m && x < m + w && y >= m && y < m + h;
      if (img.at(x, y) != bare.at(x, y)) ++(inside ? inside_changed : outside_changed);
    }
  EXPECT_EQ(outside_changed, 0);         // the frame, title, scale bar and legend untouched
  EXPECT_GT(inside_changed, w * h / 2);  // the big region's fill covers the map
}

TEST(MapPicture, InformativeNodesAreFrontierNodesOfHighGain) {
  RoadmapOverlay r;
  r.nodes = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}};
  r.frontier = {false, true, true, true, true};
  r.gain = {100, 40, 9, 10, std::numeric_limits<double>::quiet_NaN()};
  // Node 0 has the highest gain but is no frontier node; the bar is a quarter of 100.
  EXPECT_EQ(informative_nodes(r), (std::vector<size_t>{1}));
  r.gain[0] = 0;
  r.gain[1] = 36;  // the highest now: the bar drops to 9
  EXPECT_EQ(informative_nodes(r), (std::vector<size_t>{1, 2, 3}));
  r.gain.clear();  // no gains: every frontier node
  EXPECT_EQ(informative_nodes(r), (std::vector<size_t>{1, 2, 3, 4}));
}

TEST(MapPicture, FadedSegmentsBlendWithTheMapBeneath) {
  map::StateGrid grid(0.1);
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 30; ++y) grid.set_state({x, y, 10}, map::VoxelState::kFree);
  MapPictureOptions o;
  o.pixels_per_column = 5;
  MapView v;
  v.hi = {4, 3};
  MapPicture pic(grid, v, o);
  const Rgb black{0, 0, 0};
  pic.add_segments({{{0, 1.5}, {4, 1.5}}}, black, 3, 0.25);
  pic.add_dots({{2, 0.5}}, black, 3, 1.0);
  const Image img = pic.render();
  const Eigen::Vector2i on = pic.pixel({1, 1.5});
  const Rgb got = img.at(on.x(), on.y());
  // A quarter of black over the free colour: darker than free, far from black.
  EXPECT_NEAR(got.r, 0.75 * o.free.r, 4);
  EXPECT_NEAR(got.g, 0.75 * o.free.g, 4);
  const Eigen::Vector2i dot = pic.pixel({2, 0.5});
  EXPECT_EQ(img.at(dot.x(), dot.y()), black);  // an opaque dot
}

}  // namespace
}  // namespace semx::evaluator
