#include "semx/evaluator/time_split_picture.hpp"

#include <cstdio>

namespace semx::evaluator {

Rgb time_use_colour(core::TimeUse use) {
  switch (use) {
    case core::TimeUse::kNew:
      return {40, 170, 60};
    case core::TimeUse::kRevisit:
      return {220, 40, 40};
    case core::TimeUse::kTurn:
      return {40, 90, 220};
    case core::TimeUse::kHover:
      return {130, 130, 130};
    case core::TimeUse::kEndGame:
      return {150, 60, 190};
  }
  return {0, 0, 0};
}

MapPicture time_split_picture(const map::StateGrid& grid, const simulator::World& world,
                              const simulator::GroundTruth* gt, const core::TimeSplitResult& split,
                              const std::string& title) {
  MapPictureOptions o;
  o.title = title;
  MapPicture pic(grid, MapView::of_world(world), o);
  if (gt) pic.underlay_ground_truth(*gt);
  for (int i = 0; i < core::kTimeUses; ++i) {
    const auto u = static_cast<core::TimeUse>(i);
    char text[96];
    std::snprintf(text, sizeof text, "%s %.0f s (%.0f %%), %.0f m", core::to_string(u),
                  split.time_s[static_cast<size_t>(i)], 100.0 * split.share(u),
                  split.distance_m[static_cast<size_t>(i)]);
    pic.add_legend(text, time_use_colour(u));
  }
  for (const core::TimeSlice& s : split.slices) {
    if (s.points.empty()) continue;
    const Rgb c = time_use_colour(s.use);
    if (s.use == core::TimeUse::kTurn || s.use == core::TimeUse::kHover) {
      pic.add_marker(s.points.back().head<2>(), c, "", s.use == core::TimeUse::kTurn ? 3 : 2);
    } else if (s.points.size() >= 2) {
      pic.add_polyline(s.points, c, 2);
    }
  }
  return pic;
}

}  // namespace semx::evaluator
