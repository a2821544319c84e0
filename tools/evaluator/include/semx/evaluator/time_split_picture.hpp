// time_split.png: the run's map (as map.png) with the flown trajectory coloured by what each
// slice of time was for (core/time_split.hpp): green where the flight brought in new space, red
// where it crossed mapped space (revisits, backtracking), blue dots where the vehicle turned in
// place, grey dots where it hovered, purple for the end game. The legend gives each use's share
// of Time_f.
#pragma once

#include <string>

#include "semx/core/time_split.hpp"
#include "semx/evaluator/map_picture.hpp"

namespace semx::evaluator {

// The colour of each use in the picture (and in the bench report's plots).
Rgb time_use_colour(core::TimeUse use);

MapPicture time_split_picture(const map::StateGrid& grid, const simulator::World& world,
                              const simulator::GroundTruth* gt, const core::TimeSplitResult& split,
                              const std::string& title);

}  // namespace semx::evaluator
