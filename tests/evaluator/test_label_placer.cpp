// The label placer: no two labels overlap, none leaves the frame or covers a blocked area, a
// label with room keeps its place beside its anchor, a crowded one moves out with a leader line
// or is left out.
#include <gtest/gtest.h>

#include <random>

#include "semx/evaluator/label_placer.hpp"

namespace semx::evaluator {
namespace {

TEST(LabelPlacer, SparseLabelsAllGoBesideTheirAnchors) {
  LabelPlacer placer({0, 0, 400, 300});
  const int anchors[4][2] = {{50, 50}, {300, 60}, {80, 250}, {320, 240}};
  for (const auto& a : anchors) {
    const LabelPlacement p = placer.place(a[0], a[1], 40, 12, 4);
    ASSERT_TRUE(p.placed);
    EXPECT_FALSE(p.leader);
    // Beside the anchor: within the gap of it on both axes, not on top of it.
    EXPECT_LE(std::min(std::abs(p.box.x0 - a[0]), std::abs(p.box.x1 - a[0])), 40);
    EXPECT_LE(std::min(std::abs(p.box.y0 - a[1]), std::abs(p.box.y1 - a[1])), 12);
    EXPECT_FALSE(p.box.overlaps({a[0], a[1], a[0] + 1, a[1] + 1}));
  }
  EXPECT_EQ(placer.placed().size(), 4u);
}

TEST(LabelPlacer, CrowdedLabelsNeverOverlapAndStayInTheFrame) {
  const PixelBox frame{0, 0, 300, 200};
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, 299), y(0, 199), w(10, 60);
  LabelPlacer placer(frame);
  const PixelBox blocked{140, 90, 160, 110};
  placer.block(blocked);
  int placed = 0, leaders = 0, skipped = 0;
  for (int i = 0; i < 200; ++i) {
    const LabelPlacement p = placer.place(x(rng), y(rng), w(rng), 12, 3);
    if (!p.placed) {
      ++skipped;
      continue;
    }
    ++placed;
    leaders += p.leader ? 1 : 0;
    EXPECT_TRUE(p.box.inside(frame));
    EXPECT_FALSE(p.box.overlaps(blocked));
  }
  const auto& boxes = placer.placed();
  ASSERT_EQ(static_cast<int>(boxes.size()), placed);
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j) EXPECT_FALSE(boxes[i].overlaps(boxes[j])) << i << " " << j;
  // 200 labels of ~35 x 12 px cannot fit in 300 x 200 px: some are left out, some moved out.
  EXPECT_GT(skipped, 0);
  EXPECT_GT(leaders, 0);
  EXPECT_GT(placed, 40);
}

TEST(LabelPlacer, LabelsAtOnePointFanOutAroundIt) {
  LabelPlacer placer({0, 0, 500, 500});
  int placed = 0, beside = 0;
  for (int i = 0; i < 30; ++i) {
    const LabelPlacement p = placer.place(250, 250, 30, 10, 4);
    placed += p.placed ? 1 : 0;
    beside += p.placed && !p.leader ? 1 : 0;
  }
  // The ring beside the anchor holds at least the four corner spots; every label after them
  // needs a leader; with room in the frame, the outer rings take more.
  EXPECT_GE(beside, 4);
  EXPECT_GT(placed, beside);
}

TEST(LabelPlacer, ALabelLargerThanTheFrameOrWithNoRoomIsLeftOut) {
  LabelPlacer placer({0, 0, 50, 20});
  EXPECT_FALSE(placer.place(10, 10, 60, 10).placed);
  EXPECT_FALSE(placer.place(10, 10, 0, 10).placed);
  placer.block({0, 0, 50, 20});
  EXPECT_FALSE(placer.place(25, 10, 10, 5).placed);
  EXPECT_TRUE(placer.placed().empty());
}

}  // namespace
}  // namespace semx::evaluator
