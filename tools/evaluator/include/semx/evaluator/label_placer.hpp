// Places text labels of a picture so that none overlaps another (or an area kept free, such as
// a marker) and none leaves the frame: greedy, in the order asked, each label taking the first
// free spot of a few around its anchor (beside it, then farther out with a leader line back to
// the anchor). A label with no free spot is left out rather than drawn over another.
//
//   LabelPlacer placer({0, 0, 800, 600});
//   placer.block({x - 5, y - 5, x + 6, y + 6});          // the start marker
//   const LabelPlacement p = placer.place({x, y}, 40, 12);
//   if (p.placed) draw the text in p.box (and a line to the anchor if p.leader)
#pragma once

#include <vector>

namespace semx::evaluator {

// A pixel rectangle [x0, x1) x [y0, y1).
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool overlaps(const PixelBox& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool inside(const PixelBox& frame) const {
    return x0 >= frame.x0 && y0 >= frame.y0 && x1 <= frame.x1 && y1 <= frame.y1;
  }
};

struct LabelPlacement {
  bool placed = false;
  PixelBox box;         // where the label goes (when placed)
  bool leader = false;  // away from its anchor: draw a line from the anchor to the box
};

class LabelPlacer {
 public:
  // Labels stay inside `frame`.
  explicit LabelPlacer(const PixelBox& frame) : frame_(frame) {}

  // An area no later label may cover (a marker, the legend).
  void block(const PixelBox& area) { taken_.push_back(area); }

  // A label of width x height pixels for the point (ax, ay), `gap` pixels clear of it; on
  // success its box is taken.
  LabelPlacement place(int ax, int ay, int width, int height, int gap = 4);

  // Every box placed so far, in order.
  const std::vector<PixelBox>& placed() const { return placed_; }

 private:
  PixelBox frame_;
  std::vector<PixelBox> taken_;   // blocked areas and placed labels
  std::vector<PixelBox> placed_;  // placed labels only
};

}  // namespace semx::evaluator
