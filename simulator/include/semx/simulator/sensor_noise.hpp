// Optional noise models of the camera's depth and semantic outputs. Both are functions of the
// frame and a seed (the simulator derives it from its seed and the frame id), so a frame's noise
// does not depend on which other frames were rendered.
#pragma once

#include <cstdint>

#include "semx/runtime/config.hpp"
#include "semx/simulator/camera_frame.hpp"

namespace semx::simulator {

// Axial noise of a structured-light / stereo sensor: z' = z + N(0, σ(z)²) with
// σ(z) = sigma_0 + sigma_2 z² (defaults after Nguyen et al. 2012's Kinect model), plus
// independent pixel dropout to kDepthInvalid. Reserved values are left as they are.
struct DepthNoiseConfig {
  bool enabled = false;
  double sigma_0 = 0.0012;  // m
  double sigma_2 = 0.0019;  // m per m²
  double dropout = 0.0;     // probability a valid pixel reads kDepthInvalid
};
void load(runtime::ConfigMap& m, DepthNoiseConfig& c);
void apply_depth_noise(Image<uint16_t>& depth, const DepthNoiseConfig& config, uint64_t seed);

// Errors of an imperfect object detector, applied to non-structural classes only:
// - each object instance visible in the frame is missed (its pixels become class/instance 0)
//   with miss_probability, else relabelled as another object class with confusion_probability;
// - Poisson(spurious_rate) false blobs per frame: discs of a random object class and a
//   spurious instance id (kSpuriousInstanceBase + k), painted over pixels that see something.
struct DetectionNoiseConfig {
  bool enabled = false;
  double miss_probability = 0.1;
  double confusion_probability = 0.05;
  double spurious_rate = 0.2;    // expected false blobs per frame
  int spurious_min_radius = 6;   // px
  int spurious_max_radius = 30;  // px
};
inline constexpr uint16_t kSpuriousInstanceBase = 65000;
void load(runtime::ConfigMap& m, DetectionNoiseConfig& c);
void apply_detection_noise(CameraFrame& frame, const DetectionNoiseConfig& config, uint64_t seed);

}  // namespace semx::simulator
