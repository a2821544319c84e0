#include "semx/evaluator/map_picture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "draw.hpp"
#include "semx/evaluator/label_placer.hpp"

namespace semx::evaluator {

namespace {
constexpr double kEps = 1e-9;
constexpr double kLabelScale = 0.42;

// A label waiting for the placer: its anchor (map pixels), text, colour and clearance.
struct PendingLabel {
  cv::Point anchor;
  std::string text;
  cv::Scalar color;
  int gap = 4;
};

// Draws `paint` onto `target` blended at `alpha`, only within `box` (target pixels) so that the
// cost follows the overlay's size, not the picture's.
template <class Paint>
void blended(cv::Mat& target, cv::Rect box, double alpha, Paint&& paint) {
  box &= cv::Rect(0, 0, target.cols, target.rows);
  if (box.area() <= 0) return;
  cv::Mat roi = target(box);
  if (alpha >= 1.0) {
    paint(roi, -box.tl());
    return;
  }
  cv::Mat layer = roi.clone();
  paint(layer, -box.tl());
  cv::addWeighted(layer, std::clamp(alpha, 0.0, 1.0), roi, 1.0 - std::clamp(alpha, 0.0, 1.0), 0, roi);
}
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
  Overlay o{Overlay::kPolyline, points, 0, color, "", false, thickness_px, 1.0};
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

void MapPicture::add_segments(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& segments,
                              Rgb color, int thickness_px, double alpha) {
  Overlay o{Overlay::kSegments, {}, 0, color, "", false, thickness_px, alpha};
  o.points.reserve(2 * segments.size());
  for (const auto& [a, b] : segments) {
    o.points.push_back(a);
    o.points.push_back(b);
  }
  overlays_.push_back(std::move(o));
}

void MapPicture::add_dots(const std::vector<Eigen::Vector2d>& points, Rgb color, int radius_px,
                          double alpha) {
  overlays_.push_back({Overlay::kDots, points, static_cast<double>(radius_px), color, "", true, 1, alpha});
}

void MapPicture::add_circle(const Eigen::Vector2d& center, double radius_m, Rgb color,
                            const std::string& label, bool filled, int thickness_px, double alpha) {
  overlays_.push_back({Overlay::kCircle, {center}, radius_m, color, label, filled, thickness_px, alpha});
}

void MapPicture::add_marker(const Eigen::Vector2d& p, Rgb color, const std::string& label, int radius_px) {
  overlays_.push_back({Overlay::kMarker, {p}, static_cast<double>(radius_px), color, label, true, 1, 1.0});
}

void MapPicture::add_text(const Eigen::Vector2d& p, const std::string& text, Rgb color) {
  overlays_.push_back({Overlay::kText, {p}, 0, color, text, false, 1, 1.0});
}

void MapPicture::add_arrow(const Eigen::Vector2d& from, const Eigen::Vector2d& to, Rgb color,
                           int thickness_px) {
  overlays_.push_back({Overlay::kArrow, {from, to}, 0, color, "", false, thickness_px, 1.0});
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
  std::vector<std::pair<std::string, Rgb>> entries;
  if (options_.legend) {
    entries = {{"free", options_.free}, {"occupied", options_.occupied}, {"unknown", options_.unknown}};
    entries.insert(entries.end(), legend_.begin(), legend_.end());
  }
  const cv::Size legend = draw::legend_size(entries);
  const int W = m + map_w + (options_.legend ? 12 + legend.width + 12 : m);
  const int H = std::max(m + map_h + m, m + legend.height + 12);
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
  // Overlays draw into the map's frame only: OpenCV clips to a view's bounds, so a region larger
  // than the map or a label near its edge never spills over the title, scale bar or legend.
  cv::Mat map = img(cv::Rect(m, m, map_w, map_h));
  const cv::Rect whole(0, 0, map_w, map_h);
  auto pt = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2i q = pixel(p);
    return cv::Point(q.x() - m, q.y() - m);
  };
  std::vector<PendingLabel> labels;
  std::vector<PixelBox> markers;  // labelled markers: no label may cover them
  // Overlays, in order.
  for (const Overlay& o : overlays_) {
    const cv::Scalar c = draw::bgr(o.color);
    const bool many =
        o.kind == Overlay::kPolyline || o.kind == Overlay::kSegments || o.kind == Overlay::kDots;
    if (!many && !(o.points.front().allFinite() && std::isfinite(o.radius))) continue;
    switch (o.kind) {
      case Overlay::kPolyline: {
        std::vector<cv::Point> pts;
        pts.reserve(o.points.size());
        for (const auto& p : o.points) {
          if (p.allFinite()) pts.push_back(pt(p));
        }
        if (pts.size() >= 2) cv::polylines(map, pts, false, c, std::max(1, o.thickness), cv::LINE_AA);
        break;
      }
      case Overlay::kSegments:
        blended(map, whole, o.alpha, [&](cv::Mat& t, cv::Point off) {
          for (size_t i = 0; i + 1 < o.points.size(); i += 2) {
            if (!o.points[i].allFinite() || !o.points[i + 1].allFinite()) continue;
            cv::line(t, pt(o.points[i]) + off, pt(o.points[i + 1]) + off, c, std::max(1, o.thickness),
                     cv::LINE_AA);
          }
        });
        break;
      case Overlay::kDots:
        blended(map, whole, o.alpha, [&](cv::Mat& t, cv::Point off) {
          const int r = std::max(1, static_cast<int>(o.radius));
          for (const auto& p : o.points) {
            if (p.allFinite()) cv::circle(t, pt(p) + off, r, c, cv::FILLED, cv::LINE_AA);
          }
        });
        break;
      case Overlay::kCircle: {
        const cv::Point p = pt(o.points[0]);
        const int r = static_cast<int>(std::lround(std::clamp(o.radius / res_ * ppc_, 1.0, 1e5)));
        const int reach = r + std::max(1, o.thickness) + 2;
        const cv::Rect box(p.x - reach, p.y - reach, 2 * reach + 1, 2 * reach + 1);
        // Blend only the circle's box: the same pixels as blending the whole map, at a cost that
        // does not grow with the picture (the viewer draws many regions a frame).
        if (o.filled) {
          blended(map, box, 0.25,
                  [&](cv::Mat& t, cv::Point off) { cv::circle(t, p + off, r, c, cv::FILLED, cv::LINE_AA); });
        }
        blended(map, box, o.alpha, [&](cv::Mat& t, cv::Point off) {
          cv::circle(t, p + off, r, c, std::max(1, o.thickness), cv::LINE_AA);
        });
        if (!o.text.empty()) labels.push_back({p, o.text, c, 3});
        break;
      }
      case Overlay::kMarker: {
        const cv::Point p = pt(o.points[0]);
        const int r = std::max(1, static_cast<int>(o.radius));
        cv::circle(map, p, r, c, cv::FILLED, cv::LINE_AA);
        cv::circle(map, p, r, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        if (!o.text.empty()) {
          markers.push_back({p.x - r - 1, p.y - r - 1, p.x + r + 2, p.y + r + 2});
          labels.push_back({p, o.text, cv::Scalar(20, 20, 20), r + 2});
        }
        break;
      }
      case Overlay::kText:
        labels.push_back({pt(o.points[0]), o.text, c, 0});
        break;
      case Overlay::kArrow: {
        if (!o.points[1].allFinite()) break;
        const cv::Point a = pt(o.points[0]), b = pt(o.points[1]);
        const double len = std::hypot(b.x - a.x, b.y - a.y);
        if (len < 1) break;
        // A head of about 10 px whatever the arrow's length.
        cv::arrowedLine(map, a, b, c, std::max(1, o.thickness), cv::LINE_AA, 0, std::min(0.6, 10.0 / len));
        break;
      }
    }
  }
  // Labels last, on top of every overlay; the latest added (drawn on top) first, so the start,
  // end or goal keep theirs when the map is crowded.
  LabelPlacer placer({0, 0, map_w, map_h});
  for (const PixelBox& b : markers) placer.block(b);
  for (auto it = labels.rbegin(); it != labels.rend(); ++it) {
    int base = 0;
    const cv::Size sz = draw::text_size(it->text, kLabelScale, 1, &base);
    const LabelPlacement at =
        placer.place(it->anchor.x, it->anchor.y, sz.width + 4, sz.height + base + 3, it->gap);
    if (!at.placed) continue;
    const cv::Rect box(at.box.x0, at.box.y0, at.box.width(), at.box.height());
    if (at.leader) {
      const cv::Point near(std::clamp(it->anchor.x, box.x, box.x + box.width - 1),
                           std::clamp(it->anchor.y, box.y, box.y + box.height - 1));
      cv::line(map, it->anchor, near, it->color, 1, cv::LINE_AA);
    }
    // A pale box under the text keeps it legible over walls and roadmap edges.
    blended(map, box, 0.7, [&](cv::Mat& t, cv::Point off) {
      cv::rectangle(t, cv::Rect(box.tl() + off, box.size()), cv::Scalar(255, 255, 255), cv::FILLED);
    });
    draw::text_left(map, it->text, {box.x + 2, box.y + 1 + sz.height}, kLabelScale, it->color);
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
  if (options_.legend) draw::legend(img, entries, {m + map_w + 12, m}, draw::Corner::kTopLeft);
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
  const Rgb start{40, 170, 60}, end{220, 30, 30};
  pic.add_legend("trajectory", kTrajectoryColour);
  if (!trajectory.empty()) {
    pic.add_polyline(trajectory, Rgb{255, 255, 255}, 6);  // a halo: the flight reads over anything
    pic.add_polyline(trajectory, kTrajectoryColour, 3);
    const Eigen::Vector2d a = trajectory.front().head<2>(), b = trajectory.back().head<2>();
    const bool apart = (a - b).norm() > 0.5;  // else one label for both
    pic.add_marker(a, start, apart ? "start" : "start, end", 6);
    pic.add_marker(b, end, apart ? "end" : "", 6);
  }
  pic.add_legend("start", start);
  pic.add_legend("end", end);
  return pic;
}

}  // namespace semx::evaluator
