// Stage 2: from a 2D detection to a 3D one. The detection's pixels with a valid depth are
// back-projected with the frame's intrinsics and pose, then filtered: PCL's voxel-grid
// downsampling, then statistical outlier removal and Euclidean clustering (cloud_filters.hpp;
// the largest cluster is the object). PCL stays inside lifter.cpp.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include "semx/semantics/config.hpp"
#include "semx/semantics/detector.hpp"
#include "semx/semantics/frame.hpp"

namespace semx::semantics {

struct Detection3D {
  runtime::SemanticClass cls = runtime::SemanticClass::kNone;
  uint16_t instance = 0;
  float score = 1.0f;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // mean of the cluster's points (world)
  Eigen::AlignedBox3d box;                             // axis-aligned bounds of the cluster (world)
  std::vector<Eigen::Vector3f> points;                 // the cluster, one point per voxel (world)
  int mask_pixels = 0;
  int depth_pixels = 0;  // back-projected pixels (after striding)
  PixelRect image_box;
};

// Why a detection produced no 3D detection (for statistics).
enum class LiftOutcome { kOk, kNoDepth, kTooFewPoints };

class ObjectLifter {
 public:
  explicit ObjectLifter(const LiftConfig& config);
  ~ObjectLifter();
  ObjectLifter(const ObjectLifter&) = delete;
  ObjectLifter& operator=(const ObjectLifter&) = delete;

  std::optional<Detection3D> lift(const Frame& frame, const Detection2D& detection,
                                  LiftOutcome* outcome = nullptr);

  // The back-projected points of a detection before any filtering (for tests and tools).
  static std::vector<Eigen::Vector3f> back_project(const Frame& frame, const Detection2D& detection,
                                                   int stride);
  // The stride lift() uses for a detection whose typical depth is z metres.
  int stride_for_depth(const runtime::PinholeCamera& camera, double z) const;

 private:
  struct Impl;
  LiftConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace semx::semantics
