#include "semx/evaluator/label_placer.hpp"

#include <algorithm>

namespace semx::evaluator {

LabelPlacement LabelPlacer::place(int ax, int ay, int width, int height, int gap) {
  LabelPlacement out;
  if (width <= 0 || height <= 0 || width > frame_.width() || height > frame_.height()) return out;
  // Rings of spots around the anchor: the first right beside it (no leader), then two more a
  // label's height farther out each, which need a leader line to say whose label it is.
  constexpr int kRings = 3;
  for (int ring = 0; ring < kRings; ++ring) {
    const int d = gap + ring * (height + 2 * gap);
    // Upper right first (the usual place of a map label), then the other corners and sides.
    const int spots[8][2] = {{ax + d, ay - d - height},         {ax + d, ay + d},
                             {ax - d - width, ay - d - height}, {ax - d - width, ay + d},
                             {ax + d, ay - height / 2},         {ax - d - width, ay - height / 2},
                             {ax - width / 2, ay - d - height}, {ax - width / 2, ay + d}};
    for (const auto& s : spots) {
      const PixelBox b{s[0], s[1], s[0] + width, s[1] + height};
      if (!b.inside(frame_)) continue;
      if (std::any_of(taken_.begin(), taken_.end(), [&](const PixelBox& t) { return t.overlaps(b); }))
        continue;
      out.placed = true;
      out.box = b;
      out.leader = ring > 0;
      taken_.push_back(b);
      placed_.push_back(b);
      return out;
    }
  }
  return out;
}

}  // namespace semx::evaluator
