#include "semx/evaluator/map_picture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "draw.hpp"

namespace semx::evaluator {

namespace {
constexpr double kEps = 1e-9;
constexpr int kLegendWidth = 250;  // the longest entry: "semantic regions, observed (NN in all)"
}  // namespace

MapView MapView::of_world(const simulator::World& world) {
  MapView v;
  v.lo = world.bounds.min.head<2>();
  v.hi = world.bounds.max.head<2>();
  // Clear of the voxels the floor's and ceiling's surfaces fall into (a hit at z = 0 lands in
  // the voxel above it as often as below), which would otherwise darken every column.
  v.z_lo = world.bounds.min.z() + 0.3;
  v.z_hi = std::max(v.z_lo, world.bounds.max.z() - 0.4);
  return v;
}

MapPicture::MapPicture(const map::StateGrid& grid, const MapView& view, MapPictureOptions options)
    : view_(view), options_(std::move(options)), res_(grid.resolution()) {
  const double inv = 1.0 / res_;
  kx0_ = static_cast<int32_t>(std::floor(view_.lo.x() * inv + kEps));
  ky0_ = static_cast<int32_t>(std::floor(view_.lo.y() * inv + kEps));
  const auto kx1 = static_cast<int32_t>(std::ceil(view_.hi.x() * inv - kEps)) - 1;
  const auto ky1 = static_cast<int32_t>(std::ceil(view_.hi.y() * inv - kEps)) - 1;
  kz0_ = static_cast<int32_t>(std::floor(view_.z_lo * inv));
  kz1_ = std::max(kz0_, static_cast<int32_t>(std::floor(view_.z_hi * inv)));
  nx_ = std::clamp(kx1 - kx0_ + 1, 1, 20000);
  ny_ = std::clamp(ky1 - ky0_ + 1, 1, 20000);
  ppc_ = options_.pixels_per_column > 0 ? options_.pixels_per_column
                                        : std::max(1, options_.max_side_px / std::max(nx_, ny_));
  cells_.assign(static_cast<size_t>(nx_) * ny_, Column::kUnknown);
  auto reader = grid.reader();
  for (int iy = 0; iy < ny_; ++iy) {
    for (int ix = 0; ix < nx_; ++ix) {
      Column c = Column::kUnknown;
      for (int32_t kz = kz0_; kz <= kz1_; ++kz) {
        const map::VoxelState s = reader.state({kx0_ + ix, ky0_ + iy, kz});
        if (s == map::VoxelState::kOccupied) {
          c = Column::kOccupied;
          break;
        }
        if (s == map::VoxelState::kFree) c = Column::kFree;
      }
      cells_[static_cast<size_t>(iy) * nx_ + ix] = c;
    }
  }
}

void MapPicture::underlay_ground_truth(const simulator::GroundTruth& gt) {
  for (int iy = 0; iy < ny_; ++iy) {
    for (int ix = 0; ix < nx_; ++ix) {
      Column& c = cells_[static_cast<size_t>(iy) * nx_ + ix];
      if (c != Column::kUnknown) continue;
      for (int32_t kz = kz0_; kz <= kz1_; ++kz) {
        const Eigen::Vector3d p((kx0_ + ix + 0.5) * res_, (ky0_ + iy + 0.5) * res_, (kz + 0.5) * res_);
        if (gt.cell(gt.key_of(p)) == simulator::GroundTruth::kOccupied) {
          c = Column::kUnmappedWall;
          break;
        }
      }
    }
  }
  legend_.emplace_back("walls not mapped", options_.unmapped_wall);
}

void MapPicture::add_polyline(const std::vector<Eigen::Vector2d>& points, Rgb color, int thickness_px) {
  Overlay o{Overlay::kPolyline, points, 0, color, "", false, thickness_px};
  overlays_.push_back(std::move(o));
}

void MapPicture::add_polyline(const std::vector<Eigen::Vector3d>& points, Rgb color, int thickness_px) {
  std::vector<Eigen::Vector2d> p2;
  p2.reserve(points.size());
  for (const auto& p : points) p2.push_back(p.head<2>());
  add_polyline(p2, color, thickness_px);
}

void MapPicture::add_segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb color,
                             int thickness_px) {
  add_polyline(std::vector<Eigen::Vector2d>{a, b}, color, thickness_px);
}

void MapPicture::add_circle(const Eigen::Vector2d& center, double radius_m, Rgb color,
                            const std::string& label, bool filled, int thickness_px) {
  overlays_.push_back({Overlay::kCircle, {center}, radius_m, color, label, filled, thickness_px});
}

void MapPicture::add_marker(const Eigen::Vector2d& p, Rgb color, const std::string& label, int radius_px) {
  overlays_.push_back({Overlay::kMarker, {p}, static_cast<double>(radius_px), color, label, true, 1});
}

void MapPicture::add_text(const Eigen::Vector2d& p, const std::string& text, Rgb color) {
  overlays_.push_back({Overlay::kText, {p}, 0, color, text, false, 1});
}

void MapPicture::add_arrow(const Eigen::Vector2d& from, const Eigen::Vector2d& to, Rgb color,
                           int thickness_px) {
  overlays_.push_back({Overlay::kArrow, {from, to}, 0, color, "", false, thickness_px});
}

void MapPicture::add_legend(const std::string& text, Rgb color) { legend_.emplace_back(text, color); }

Eigen::Vector2i MapPicture::pixel(const Eigen::Vector2d& p) const {
  // Clamped so that lround stays within int; OpenCV clips what lies outside the image.
  constexpr double kFar = 1e6;
  const double fx = std::clamp((p.x() / res_ - kx0_) * ppc_, -kFar, kFar);
  const double fy = std::clamp((ny_ - (p.y() / res_ - ky0_)) * ppc_, -kFar, kFar);
  if (!std::isfinite(fx) || !std::isfinite(fy)) return {-static_cast<int>(kFar), -static_cast<int>(kFar)};
  return {options_.margin_px + static_cast<int>(std::lround(fx)),
          options_.margin_px + static_cast<int>(std::lround(fy))};
}

int64_t MapPicture::count(Column c) const { return std::count(cells_.begin(), cells_.end(), c); }

Image MapPicture::render() const {
  const int m = options_.margin_px;
  const int map_w = nx_ * ppc_, map_h = ny_ * ppc_;
  const int W = m + map_w + (options_.legend ? kLegendWidth : m);
  const int H = m + map_h + m;
  cv::Mat img(H, W, CV_8UC3, draw::bgr(options_.background));
  // Columns.
  const cv::Scalar colors[4] = {draw::bgr(options_.unknown), draw::bgr(options_.free),
                                draw::bgr(options_.occupied), draw::bgr(options_.unmapped_wall)};
  for (int iy = 0; iy < ny_; ++iy) {
    for (int ix = 0; ix < nx_; ++ix) {
      const int x = m + ix * ppc_, y = m + (ny_ - 1 - iy) * ppc_;
      cv::rectangle(img, cv::Rect(x, y, ppc_, ppc_), colors[static_cast<int>(column(ix, iy))], cv::FILLED);
    }
  }
  cv::rectangle(img, {m - 1, m - 1}, {m + map_w, m + map_h}, cv::Scalar(90, 90, 90), 1);
  auto pt = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2i q = pixel(p);
    return cv::Point(q.x(), q.y());
  };
  // Overlays, in order.
  for (const Overlay& o : overlays_) {
    const cv::Scalar c = draw::bgr(o.color);
    if (o.kind != Overlay::kPolyline && !(o.points.front().allFinite() && std::isfinite(o.radius))) continue;
    switch (o.kind) {
      case Overlay::kPolyline: {
        std::vector<cv::Point> pts;
        pts.reserve(o.points.size());
        for (const auto& p : o.points) {
          if (p.allFinite()) pts.push_back(pt(p));
        }
        if (pts.size() >= 2) cv::polylines(img, pts, false, c, std::max(1, o.thickness), cv::LINE_AA);
        break;
      }
      case Overlay::kCircle: {
        const cv::Point p = pt(o.points[0]);
        const int r = static_cast<int>(std::lround(std::clamp(o.radius / res_ * ppc_, 1.0, 1e5)));
        if (o.filled) {
          // Blend only the circle's box: the same pixels as blending the whole image, at a
          // cost that does not grow with the picture (the viewer draws many regions a frame).
          const cv::Rect box =
              cv::Rect(p.x - r - 2, p.y - r - 2, 2 * r + 5, 2 * r + 5) & cv::Rect(0, 0, W, H);
          if (box.area() > 0) {
            cv::Mat roi = img(box);
            cv::Mat layer = roi.clone();
            cv::circle(layer, p - box.tl(), r, c, cv::FILLED, cv::LINE_AA);
            cv::addWeighted(layer, 0.25, roi, 0.75, 0, roi);
          }
        }
        cv::circle(img, p, r, c, std::max(1, o.thickness), cv::LINE_AA);
        draw::text_left(img, o.text,
                        {p.x + static_cast<int>(r * 0.71) + 3, p.y - static_cast<int>(r * 0.71) - 3}, 0.42,
                        c);
        break;
      }
      case Overlay::kMarker: {
        const cv::Point p = pt(o.points[0]);
        const int r = std::max(1, static_cast<int>(o.radius));
        cv::circle(img, p, r, c, cv::FILLED, cv::LINE_AA);
        cv::circle(img, p, r, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        draw::text_left(img, o.text, {p.x + r + 3, p.y - r - 1}, 0.45, cv::Scalar(20, 20, 20));
        break;
      }
      case Overlay::kText:
        draw::text_left(img, o.text, pt(o.points[0]), 0.45, c);
        break;
      case Overlay::kArrow: {
        if (!o.points[1].allFinite()) break;
        const cv::Point a = pt(o.points[0]), b = pt(o.points[1]);
        const double len = std::hypot(b.x - a.x, b.y - a.y);
        if (len < 1) break;
        // A head of about 10 px whatever the arrow's length.
        cv::arrowedLine(img, a, b, c, std::max(1, o.thickness), cv::LINE_AA, 0, std::min(0.6, 10.0 / len));
        break;
      }
    }
  }
  // Title, scale bar, legend.
  draw::text_left(img, options_.title, {m, m - 12}, 0.55, cv::Scalar(20, 20, 20));
  double bar_m = 1.0;
  for (const double b : {0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0}) {
    bar_m = b;
    if (b / res_ * ppc_ >= 60) break;
  }
  const int bar_px = static_cast<int>(std::lround(bar_m / res_ * ppc_));
  const int by = m + map_h + m / 2 + 2;
  cv::line(img, {m, by}, {m + bar_px, by}, cv::Scalar(0, 0, 0), 2);
  cv::line(img, {m, by - 4}, {m, by + 4}, cv::Scalar(0, 0, 0), 1);
  cv::line(img, {m + bar_px, by - 4}, {m + bar_px, by + 4}, cv::Scalar(0, 0, 0), 1);
  char b[64];
  std::snprintf(b, sizeof b, "%g m", bar_m);
  draw::text_left(img, b, {m + bar_px + 8, by + 5}, 0.45, cv::Scalar(20, 20, 20));
  if (options_.legend) {
    std::vector<std::pair<std::string, Rgb>> entries = {
        {"free", options_.free}, {"occupied", options_.occupied}, {"unknown", options_.unknown}};
    entries.insert(entries.end(), legend_.begin(), legend_.end());
    draw::legend(img, entries, {m + map_w + 12, m}, draw::Corner::kTopLeft);
  }
  return draw::to_image(img);
}

void MapPicture::write_png(const std::string& path) const { evaluator::write_png(render(), path); }

MapPicture run_map_picture(const map::StateGrid& grid, const simulator::World& world,
                           const simulator::GroundTruth* gt, const std::vector<Eigen::Vector3d>& trajectory,
                           const std::string& title, const std::function<void(MapPicture&)>& beneath) {
  MapPictureOptions o;
  o.title = title;
  MapPicture pic(grid, MapView::of_world(world), o);
  if (gt) pic.underlay_ground_truth(*gt);
  if (beneath) beneath(pic);
  const Rgb path{30, 90, 220}, start{40, 170, 60}, end{220, 50, 40};
  pic.add_legend("trajectory", path);
  if (!trajectory.empty()) {
    pic.add_polyline(trajectory, path, 2);
    const Eigen::Vector2d a = trajectory.front().head<2>(), b = trajectory.back().head<2>();
    const bool apart = (a - b).norm() > 0.5;  // else one label for both
    pic.add_marker(a, start, apart ? "start" : "start, end");
    pic.add_marker(b, end, apart ? "end" : "", 4);
  }
  pic.add_legend("start", start);
  pic.add_legend("end", end);
  return pic;
}

}  // namespace semx::evaluator
