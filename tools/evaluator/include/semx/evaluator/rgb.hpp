// Colours and images of the evaluator's pictures, without OpenCV in the interface.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace semx::evaluator {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb& a, const Rgb& b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
  friend bool operator!=(const Rgb& a, const Rgb& b) { return !(a == b); }
};

// 8-bit RGB, row-major, 3 bytes per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;

  Image() = default;
  Image(int w, int h, Rgb fill = {255, 255, 255});
  Rgb at(int x, int y) const {
    const size_t i = 3 * (static_cast<size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
  void set(int x, int y, Rgb c) {
    const size_t i = 3 * (static_cast<size_t>(y) * width + x);
    rgb[i] = c.r;
    rgb[i + 1] = c.g;
    rgb[i + 2] = c.b;
  }
};

// Writes a PNG; throws RunFolderError (run_folder.hpp) naming the file on failure.
void write_png(const Image& image, const std::string& path);

// A palette of distinct colours for series and labels (cycles).
Rgb palette(int i);

}  // namespace semx::evaluator
