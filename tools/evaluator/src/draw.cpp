#include "draw.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace semx::evaluator::draw {

namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
}

void text_left(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
               int thickness) {
  if (s.empty()) return;
  cv::putText(m, s, at, kFont, scale, color, thickness, cv::LINE_AA);
}

void text_centered(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
                   int thickness) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, thickness, &base);
  text_left(m, s, {at.x - sz.width / 2, at.y}, scale, color, thickness);
}

void text_right(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
                int thickness) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, thickness, &base);
  text_left(m, s, {at.x - sz.width, at.y}, scale, color, thickness);
}

void text_vertical(cv::Mat& m, const std::string& s, cv::Point center, double scale, cv::Scalar color) {
  if (s.empty()) return;
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, 1, &base);
  cv::Mat t(sz.height + base + 4, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(t, s, {2, sz.height + 2}, kFont, scale, color, 1, cv::LINE_AA);
  cv::Mat r;
  cv::rotate(t, r, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect dst(center.x - r.cols / 2, center.y - r.rows / 2, r.cols, r.rows);
  const cv::Rect clipped = dst & cv::Rect(0, 0, m.cols, m.rows);
  if (clipped.area() == 0) return;
  r(cv::Rect(clipped.x - dst.x, clipped.y - dst.y, clipped.width, clipped.height)).copyTo(m(clipped));
}

cv::Size text_size(const std::string& s, double scale, int thickness, int* baseline) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, thickness, &base);
  if (baseline) *baseline = base;
  return sz;
}

void dashed_line(cv::Mat& m, cv::Point a, cv::Point b, cv::Scalar color, int thickness, int dash, int gap) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  if (len <= 0) return;
  const double ux = (b.x - a.x) / len, uy = (b.y - a.y) / len;
  for (double s = 0; s < len; s += dash + gap) {
    const double e = std::min(len, s + dash);
    cv::line(m, {static_cast<int>(std::lround(a.x + ux * s)), static_cast<int>(std::lround(a.y + uy * s))},
             {static_cast<int>(std::lround(a.x + ux * e)), static_cast<int>(std::lround(a.y + uy * e))},
             color, thickness, cv::LINE_AA);
  }
}

namespace {
constexpr double kLegendScale = 0.45;
constexpr int kLegendLine = 18, kSwatch = 22, kLegendPad = 6;
}  // namespace

cv::Size legend_size(const std::vector<std::pair<std::string, Rgb>>& entries) {
  if (entries.empty()) return {0, 0};
  int w = 0, base = 0;
  for (const auto& e : entries)
    w = std::max(w, cv::getTextSize(e.first, kFont, kLegendScale, 1, &base).width);
  return {kLegendPad + kSwatch + 6 + w + kLegendPad,
          kLegendPad + kLegendLine * static_cast<int>(entries.size()) + kLegendPad / 2};
}

void legend(cv::Mat& m, const std::vector<std::pair<std::string, Rgb>>& entries, cv::Point anchor,
            Corner corner) {
  if (entries.empty()) return;
  const cv::Size size = legend_size(entries);
  const int bw = size.width, bh = size.height, pad = kLegendPad, line_h = kLegendLine, swatch = kSwatch;
  int x = anchor.x, y = anchor.y;
  if (corner == Corner::kTopRight || corner == Corner::kBottomRight) x -= bw;
  if (corner == Corner::kBottomLeft || corner == Corner::kBottomRight) y -= bh;
  cv::rectangle(m, {x, y}, {x + bw, y + bh}, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(m, {x, y}, {x + bw, y + bh}, cv::Scalar(120, 120, 120), 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int cy = y + pad + line_h * static_cast<int>(i) + line_h / 2;
    cv::rectangle(m, {x + pad, cy - 4}, {x + pad + swatch, cy + 4}, bgr(entries[i].second), cv::FILLED);
    cv::rectangle(m, {x + pad, cy - 4}, {x + pad + swatch, cy + 4}, cv::Scalar(90, 90, 90), 1);
    text_left(m, entries[i].first, {x + pad + swatch + 6, cy + 5}, kLegendScale, cv::Scalar(30, 30, 30));
  }
}

Image to_image(const cv::Mat& bgr8) {
  Image img(bgr8.cols, bgr8.rows);
  for (int y = 0; y < bgr8.rows; ++y) {
    const auto* row = bgr8.ptr<uint8_t>(y);
    for (int x = 0; x < bgr8.cols; ++x) img.set(x, y, {row[3 * x + 2], row[3 * x + 1], row[3 * x]});
  }
  return img;
}

}  // namespace semx::evaluator::draw
