// What the viewer added to evaluator::MapPicture: arrows, a fixed number of pixels per column,
// and overlays that are not finite or lie far outside the picture (skipped or clipped, never an
// overflow).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "semx/evaluator/map_picture.hpp"

namespace semx::evaluator {
namespace {

MapView area(double x1, double y1) {
  MapView v;
  v.lo = {0, 0};
  v.hi = {x1, y1};
  v.z_lo = 0.5;
  v.z_hi = 1.5;
  return v;
}

TEST(MapPictureOverlays, PixelsPerColumnOverridesTheFit) {
  map::StateGrid grid(0.1);
  MapPictureOptions o;
  o.max_side_px = 100;
  o.pixels_per_column = 7;
  const MapPicture pic(grid, area(4, 2), o);
  EXPECT_EQ(pic.pixels_per_column(), 7);
  const Image img = pic.render();
  EXPECT_GE(img.width, 40 * 7);
  EXPECT_EQ(pic.pixel({1, 0}).x() - pic.pixel({0, 0}).x(), 70);
  o.pixels_per_column = 0;
  EXPECT_EQ(MapPicture(grid, area(4, 2), o).pixels_per_column(), 2);  // 100 px / 40 columns
}

TEST(MapPictureOverlays, AnArrowPointsFromItsStart) {
  map::StateGrid grid(0.1);
  MapPictureOptions o;
  o.pixels_per_column = 10;
  MapPicture pic(grid, area(4, 4), o);
  const Rgb red{230, 10, 10};
  pic.add_arrow({1, 2}, {3, 2}, red, 3);
  const Image img = pic.render();
  EXPECT_EQ(img.at(pic.pixel({2, 2}).x(), pic.pixel({2, 2}).y()), red);
  EXPECT_EQ(img.at(pic.pixel({1.2, 2}).x(), pic.pixel({1.2, 2}).y()), red);
  // The head: pixels beside the shaft near its end, none near its start.
  const Eigen::Vector2i tip = pic.pixel({3, 2});
  int head = 0, tail = 0;
  const Eigen::Vector2i start = pic.pixel({1, 2});
  for (int dy = 3; dy <= 6; ++dy) {
    for (int dx = -10; dx <= 0; ++dx) {
      head += img.at(tip.x() + dx, tip.y() + dy) == red;
      tail += img.at(start.x() - dx, start.y() + dy) == red;
    }
  }
  EXPECT_GT(head, 0);
  EXPECT_EQ(tail, 0);
}

TEST(MapPictureOverlays, NonFiniteAndFarOverlaysAreSkippedOrClipped) {
  map::StateGrid grid(0.1);
  grid.set_state({5, 5, 10}, map::VoxelState::kFree);
  MapPictureOptions o;
  o.pixels_per_column = 5;
  MapPicture pic(grid, area(3, 3), o);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const Rgb c{0, 200, 0};
  pic.add_circle({nan, 1}, 0.5, c, "nan");
  pic.add_circle({1, 1}, nan, c, "nan radius");
  pic.add_circle({1, 1}, 1e300, c, "", true);
  pic.add_marker({inf, 0}, c, "inf");
  pic.add_marker({1e300, -1e300}, c, "far");
  pic.add_text({nan, nan}, "nan", c);
  pic.add_arrow({1, 1}, {nan, 1}, c);
  pic.add_arrow({1, 1}, {1e300, 1}, c);
  pic.add_segment({-1e300, 1.5}, {1e300, 1.5}, c, 1);
  pic.add_polyline(std::vector<Eigen::Vector2d>{{0.5, 0.5}, {nan, 0}, {2.5, 0.5}}, c, 1);
  const Image img = pic.render();
  EXPECT_GT(img.width, 0);
  // The far segment is clipped to the picture: drawn across it at y = 1.5 m.
  const Eigen::Vector2i m = pic.pixel({1.5, 1.5});
  const Rgb got = img.at(m.x(), m.y());
  EXPECT_TRUE(std::abs(got.r - c.r) < 30 && std::abs(got.g - c.g) < 30 && std::abs(got.b - c.b) < 30);
  // Far points map to far pixels, not to wrapped-around ones.
  EXPECT_LT(pic.pixel({-1e300, 0}).x(), -1000);
  EXPECT_GT(pic.pixel({1e300, 0}).x(), 1000);
  EXPECT_GT(pic.pixel({0, -1e300}).y(), 1000);
}

}  // namespace
}  // namespace semx::evaluator
