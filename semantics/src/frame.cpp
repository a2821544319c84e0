#include "semx/semantics/frame.hpp"

#include <cmath>

namespace semx::semantics {

namespace {
bool finite(double x) { return std::isfinite(x); }
}  // namespace

std::string validate(const Frame& f) {
  const auto& c = f.camera;
  if (c.width <= 0 || c.height <= 0 || c.width > kMaxImageSide || c.height > kMaxImageSide) {
    return "image size " + std::to_string(c.width) + "x" + std::to_string(c.height) + " out of range";
  }
  if (!(finite(c.fx) && finite(c.fy) && c.fx > 0 && c.fy > 0 && finite(c.cx) && finite(c.cy))) {
    return "intrinsics not finite or not positive";
  }
  if (!(finite(c.min_range) && finite(c.max_range) && c.min_range >= 0 && c.max_range > c.min_range)) {
    return "depth range not finite or empty";
  }
  const Eigen::Matrix4d& m = f.pose.matrix();
  if (!m.allFinite()) return "pose not finite";
  const Eigen::Matrix3d r = f.pose.linear();
  if (!((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
        r.determinant() > 0)) {
    return "pose rotation is not a rotation";
  }
  const std::size_t n = f.pixels();
  if (f.depth.size() != n) {
    return "depth has " + std::to_string(f.depth.size()) + " pixels, expected " + std::to_string(n);
  }
  if (!f.class_label.empty() && f.class_label.size() != n) {
    return "class labels have " + std::to_string(f.class_label.size()) + " pixels, expected " +
           std::to_string(n);
  }
  if (!f.instance_label.empty() && f.instance_label.size() != n) {
    return "instance labels have " + std::to_string(f.instance_label.size()) + " pixels, expected " +
           std::to_string(n);
  }
  if (!f.instance_label.empty() && f.class_label.empty()) return "instance labels without class labels";
  if (!f.rgb.empty() && f.rgb.size() != 3 * n) {
    return "rgb has " + std::to_string(f.rgb.size()) + " bytes, expected " + std::to_string(3 * n);
  }
  return "";
}

}  // namespace semx::semantics
