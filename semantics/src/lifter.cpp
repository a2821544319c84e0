// PCL lives here only: the voxel grid. The neighbour filters are cloud_filters' (nanoflann).
#include "semx/semantics/lifter.hpp"

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "semx/semantics/cloud_filters.hpp"

#include <algorithm>
#include <cmath>

namespace semx::semantics {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

struct ObjectLifter::Impl {
  Cloud::Ptr raw{new Cloud};
  Cloud::Ptr down{new Cloud};
  pcl::VoxelGrid<pcl::PointXYZ> voxel;
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> filtered;
  std::vector<float> depths;
};

ObjectLifter::ObjectLifter(const LiftConfig& config) : config_(config), impl_(std::make_unique<Impl>()) {
  const float leaf = static_cast<float>(config.voxel_size);
  impl_->voxel.setLeafSize(leaf, leaf, leaf);
}

ObjectLifter::~ObjectLifter() = default;

int ObjectLifter::stride_for_depth(const runtime::PinholeCamera& camera, double z) const {
  if (!(z > 0)) return 1;
  // A pixel covers z / fx metres; sample every voxel_size / 2.
  const double s = std::floor(config_.voxel_size * std::min(camera.fx, camera.fy) / (2.0 * z));
  return static_cast<int>(std::clamp(s, 1.0, static_cast<double>(config_.max_pixel_stride)));
}

namespace {

inline bool usable_depth(uint16_t d, const runtime::PinholeCamera& cam, double& z) {
  if (d == runtime::kDepthInvalid || d == runtime::kDepthNoReturn) return false;
  z = d * 1e-3;
  return z >= cam.min_range && z <= cam.max_range;
}

}  // namespace

std::vector<Eigen::Vector3f> ObjectLifter::back_project(const Frame& frame, const Detection2D& det,
                                                        int stride) {
  std::vector<Eigen::Vector3f> pts;
  const auto& cam = frame.camera;
  const Eigen::Matrix3d r = frame.pose.linear();
  const Eigen::Vector3d t = frame.pose.translation();
  stride = std::max(1, stride);
  for (int v = det.box.y; v < det.box.y + det.box.height; v += stride) {
    if (v < 0 || v >= cam.height) continue;
    const uint16_t* drow = frame.depth.data() + static_cast<std::size_t>(v) * cam.width;
    for (int u = det.box.x; u < det.box.x + det.box.width; u += stride) {
      if (u < 0 || u >= cam.width || !det.at(u, v)) continue;
      double z;
      if (!usable_depth(drow[u], cam, z)) continue;
      pts.push_back((r * cam.unproject(u, v, z) + t).cast<float>());
    }
  }
  return pts;
}

std::optional<Detection3D> ObjectLifter::lift(const Frame& frame, const Detection2D& det,
                                              LiftOutcome* outcome) {
  auto fail = [&](LiftOutcome o) -> std::optional<Detection3D> {
    if (outcome) *outcome = o;
    return std::nullopt;
  };
  if (outcome) *outcome = LiftOutcome::kOk;
  const auto& cam = frame.camera;
  if (det.box.area() <= 0 || det.mask.size() != static_cast<std::size_t>(det.box.area()) ||
      frame.depth.size() != frame.pixels() || det.box.x < 0 || det.box.y < 0 ||
      det.box.x + det.box.width > cam.width || det.box.y + det.box.height > cam.height) {
    return fail(LiftOutcome::kNoDepth);
  }

  // Typical depth from a sparse sample, to choose the stride.
  auto& depths = impl_->depths;
  depths.clear();
  const int probe = std::max(1, static_cast<int>(std::sqrt(det.area / 64.0)));
  for (int v = det.box.y; v < det.box.y + det.box.height; v += probe) {
    for (int u = det.box.x; u < det.box.x + det.box.width; u += probe) {
      double z;
      if (det.at(u, v) && usable_depth(frame.depth[static_cast<std::size_t>(v) * cam.width + u], cam, z)) {
        depths.push_back(static_cast<float>(z));
      }
    }
  }
  if (depths.empty()) return fail(LiftOutcome::kNoDepth);
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const int stride = stride_for_depth(cam, depths[depths.size() / 2]);

  // Back-projection straight into the PCL cloud.
  Cloud& raw = *impl_->raw;
  raw.clear();
  const Eigen::Matrix3d r = frame.pose.linear();
  const Eigen::Vector3d t = frame.pose.translation();
  // Rows are sampled three times as densely as columns: the tops of objects seen from above at
  // a grazing angle stretch far in depth over few rows, and would otherwise fall apart into
  // rows farther apart than the cluster tolerance.
  const int row_stride = std::max(1, stride / 3);
  for (int v = det.box.y; v < det.box.y + det.box.height; v += row_stride) {
    const uint16_t* drow = frame.depth.data() + static_cast<std::size_t>(v) * cam.width;
    for (int u = det.box.x; u < det.box.x + det.box.width; u += stride) {
      double z;
      if (!det.at(u, v) || !usable_depth(drow[u], cam, z)) continue;
      const Eigen::Vector3d p = r * cam.unproject(u, v, z) + t;
      raw.push_back(
          pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())));
    }
  }
  const int depth_pixels = static_cast<int>(raw.size());
  if (depth_pixels < config_.min_points) return fail(LiftOutcome::kTooFewPoints);

  impl_->voxel.setInputCloud(impl_->raw);
  impl_->voxel.filter(*impl_->down);
  auto& points = impl_->points;
  points.clear();
  points.reserve(impl_->down->size());
  for (const auto& q : *impl_->down) points.emplace_back(q.x, q.y, q.z);
  if (config_.outlier_neighbours > 0 && static_cast<int>(points.size()) > config_.outlier_neighbours + 1) {
    auto& filtered = impl_->filtered;
    filtered.clear();
    for (const uint32_t i :
         remove_statistical_outliers(points, config_.outlier_neighbours, config_.outlier_stddev)) {
      filtered.push_back(points[i]);
    }
    points.swap(filtered);
  }
  if (static_cast<int>(points.size()) < config_.min_points) return fail(LiftOutcome::kTooFewPoints);

  const auto found = euclidean_clusters(points, config_.cluster_tolerance);
  if (found.empty() || static_cast<int>(found.front().size()) < config_.min_points) {
    return fail(LiftOutcome::kTooFewPoints);
  }
  const auto& best = found.front();

  Detection3D d;
  d.cls = det.cls;
  d.instance = det.instance;
  d.score = det.score;
  d.mask_pixels = det.area;
  d.depth_pixels = depth_pixels;
  d.image_box = det.box;
  d.points.reserve(best.size());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const uint32_t i : best) {
    const Eigen::Vector3f& p = points[i];
    d.points.push_back(p);
    d.box.extend(p.cast<double>());
    sum += p.cast<double>();
  }
  d.centroid = sum / static_cast<double>(best.size());
  return d;
}

}  // namespace semx::semantics
