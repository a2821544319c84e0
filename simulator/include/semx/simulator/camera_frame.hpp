// One rendered RGB-D + label frame and the pose it was taken from.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

#include "semx/runtime/pinhole_camera.hpp"
#include "semx/simulator/image.hpp"

namespace semx::simulator {

// Which images a render produces; depth and labels come from the same pass, RGB costs one more
// lookup per pixel.
enum RenderChannels : unsigned {
  kRenderDepth = 1u << 0,
  kRenderLabels = 1u << 1,
  kRenderRgb = 1u << 2,
  kRenderAll = kRenderDepth | kRenderLabels | kRenderRgb,
  // The RGB image as runs of one colour (CameraFrame::rgb_runs). Flat shading makes a frame a
  // few thousand runs, which is all a run-length encoder needs: the simulator node asks for this
  // instead of kRenderRgb and spares writing a 0.9 MB image only to scan it again.
  kRenderRgbRuns = 1u << 3,
};

// `length` pixels of one colour, in row-major order.
struct RgbRun {
  uint32_t length = 0;
  Rgb colour;
  friend bool operator==(const RgbRun& a, const RgbRun& b) {
    return a.length == b.length && a.colour == b.colour;
  }
};

struct CameraFrame {
  int64_t utime = 0;
  int64_t frame_id = 0;
  runtime::PinholeCamera camera;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // optical frame in the world
  unsigned channels = 0;                                   // RenderChannels present

  // Depth: z in mm; kDepthInvalid below min_range, kDepthNoReturn when nothing within max_range.
  Image<uint16_t> depth;
  // Class ids (runtime::SemanticClass) and instance ids of the surface seen; 0 where nothing is
  // within max_range. Pixels closer than min_range keep their labels (the surface is seen even
  // though its depth is not measured).
  Image<uint16_t> class_label;
  Image<uint16_t> instance_label;
  Image<Rgb> rgb;
  // With kRenderRgbRuns: the RGB image as maximal runs (neighbouring runs differ in colour)
  // whose lengths add up to width * height. `rgb` is filled only with kRenderRgb.
  std::vector<RgbRun> rgb_runs;
};

// The maximal runs of an RGB image, in row-major order.
inline std::vector<RgbRun> rgb_runs(const Image<Rgb>& image) {
  std::vector<RgbRun> runs;
  for (const Rgb& c : image.data) {
    if (!runs.empty() && runs.back().colour == c) {
      ++runs.back().length;
    } else {
      runs.push_back({1, c});
    }
  }
  return runs;
}

// Background colour of RGB pixels that see nothing within the render's far limit.
inline constexpr Rgb kBackgroundRgb{25, 25, 35};

}  // namespace semx::simulator
