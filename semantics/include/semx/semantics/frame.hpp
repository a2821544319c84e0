// One camera capture as the semantics library sees it: the pinhole model, the pose of the
// optical frame in the world (pinhole_camera.hpp's convention), and the images of that capture.
// No LCM: the node fills it from CAMERA_DEPTH / CAMERA_LABELS / CAMERA_RGB, tools and tests from
// the simulator's CameraFrame.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "semx/runtime/pinhole_camera.hpp"

namespace semx::semantics {

struct Frame {
  int64_t utime = 0;  // message time, µs
  int64_t frame_id = 0;
  runtime::PinholeCamera camera;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // optical frame in the world

  // Row-major, width*height each; an empty vector means "not available".
  std::vector<uint16_t> depth;           // mm; kDepthInvalid / kDepthNoReturn reserved
  std::vector<uint16_t> class_label;     // runtime::SemanticClass ids
  std::vector<uint16_t> instance_label;  // 0 = unknown (may be empty when classes are given)
  std::vector<uint8_t> rgb;              // R, G, B interleaved (width*height*3)

  std::size_t pixels() const { return static_cast<std::size_t>(camera.width) * camera.height; }
  bool has_labels() const { return !class_label.empty(); }
  bool has_rgb() const { return !rgb.empty(); }
};

// Largest image side accepted (a guard against absurd sizes in messages).
inline constexpr int kMaxImageSide = 8192;

// Why `f` cannot be processed, or "" when it can: image sizes that disagree with the camera,
// no depth, non-finite or non-positive intrinsics, an empty or inverted range, a pose that is
// not finite or not a rotation.
std::string validate(const Frame& f);

}  // namespace semx::semantics
