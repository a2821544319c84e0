// A grid of pictures read from PNG files, each scaled down into a tile of the same size under
// its own title, with a title over the grid (the bench's maps_WORLD.png: one map.png per
// planner). A file that is missing or not a picture gets a grey tile saying so, and is listed
// in `missing`: one absent run folder does not cost the others' pictures.
#pragma once

#include <string>
#include <vector>

#include "semx/evaluator/rgb.hpp"

namespace semx::evaluator {

struct MontageTile {
  std::string png;    // the picture's file
  std::string title;  // the line above it
};

struct MontageOptions {
  std::string title;
  int tile_width = 600;  // pixels; the height follows the first readable picture's aspect
  int columns = 3;       // at most; fewer tiles, fewer columns
};

struct Montage {
  Image image;
  std::vector<std::string> missing;  // "FILE: why" per tile drawn without its picture
};

Montage render_montage(const std::vector<MontageTile>& tiles, const MontageOptions& options = {});

}  // namespace semx::evaluator
