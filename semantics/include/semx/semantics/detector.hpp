// Stage 1: 2D detection. A Detector turns a frame into object masks; the rest of the pipeline
// only sees Detection2D, so a learned detector replaces the label-image one without touching it.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "semx/runtime/semantic_classes.hpp"
#include "semx/semantics/config.hpp"
#include "semx/semantics/frame.hpp"

namespace semx::semantics {

struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
  int area() const { return width * height; }
};

struct Detection2D {
  runtime::SemanticClass cls = runtime::SemanticClass::kNone;
  uint16_t instance = 0;  // the label image's instance id when the detector knows it, else 0
  float score = 1.0f;     // 0..1
  PixelRect box;          // bounding box in the image
  // box.width * box.height bytes, row-major inside `box`: non-zero = the object's pixel.
  std::vector<uint8_t> mask;
  int area = 0;  // mask pixels
  bool at(int u, int v) const {
    return mask[static_cast<std::size_t>(v - box.y) * box.width + (u - box.x)] != 0;
  }
};

class DetectorError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Detector {
 public:
  virtual ~Detector() = default;
  virtual std::string name() const = 0;
  virtual bool needs_labels() const = 0;
  virtual bool needs_rgb() const = 0;
  // Detections of enabled object classes. Never throws on a frame that passed validate(); a
  // frame without the images it needs gives no detections.
  virtual std::vector<Detection2D> detect(const Frame& frame) = 0;
};

// Masks from a label image (the simulator's label camera, or any per-pixel segmentation):
// per class (and instance, with use_instances) a mask, a morphological opening, connected
// components, components below min_area_px dropped. With use_instances the components of one
// instance that survive form one detection; without, each component is one.
class LabelDetector : public Detector {
 public:
  LabelDetector(const DetectorConfig& config, const RegionConfig& classes);
  std::string name() const override { return "labels"; }
  bool needs_labels() const override { return true; }
  bool needs_rgb() const override { return false; }
  std::vector<Detection2D> detect(const Frame& frame) override;

  // The same pipeline on any label image (used by the DNN detector on its arg-max image).
  // `scores` (optional, per pixel) become the detections' mean score.
  std::vector<Detection2D> detect_labels(int width, int height, const uint16_t* classes,
                                         const uint16_t* instances, const float* scores);

 private:
  DetectorConfig config_;
  std::array<bool, kClassCount> enabled_{};
};

// A semantic-segmentation network (ONNX, OpenCV DNN) on the RGB image: input
// dnn.input_width x dnn.input_height, output 1 x C x H x W scores (softmax applied if they do
// not already sum to 1), channel c meaning class dnn.classes[c]. The arg-max image, resized to
// the frame, goes through LabelDetector's masks. The constructor throws DetectorError if the
// model file is missing or cannot be loaded.
class DnnDetector : public Detector {
 public:
  DnnDetector(const DetectorConfig& config, const RegionConfig& classes);
  ~DnnDetector() override;
  std::string name() const override { return "dnn"; }
  bool needs_labels() const override { return false; }
  bool needs_rgb() const override { return true; }
  std::vector<Detection2D> detect(const Frame& frame) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The detector named by config.detector.type.
std::unique_ptr<Detector> make_detector(const SemanticsConfig& config);

// OpenCV's worker threads for the detectors (process-wide). The semantics process and its
// benchmark use 1: its budget is one core, and waking workers for small masks costs more than
// it saves.
void set_detector_threads(int threads);

}  // namespace semx::semantics
