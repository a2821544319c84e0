#include "semx/evaluator/coverage_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "draw.hpp"

namespace semx::evaluator {

PlotSeries coverage_series(const std::vector<CoverageSample>& samples, const std::string& label) {
  PlotSeries s;
  s.label = label;
  s.points.reserve(samples.size());
  for (const auto& c : samples) s.points.emplace_back(c.t_s, c.coverage_pct);
  return s;
}

std::vector<double> nice_ticks(double max, int target) {
  if (!(max > 0) || !std::isfinite(max)) max = 1.0;
  target = std::max(1, target);
  const double raw = max / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * mag;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw * (1 - 1e-9)) {
      step = m * mag;
      break;
    }
  }
  std::vector<double> t;
  for (int i = 0; i * step <= max * (1 + 1e-9); ++i) t.push_back(i * step);
  return t;
}

namespace {

std::string tick_label(double v, double step) {
  char b[32];
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

}  // namespace

Image render_coverage_plot(const std::vector<PlotSeries>& series, const CoveragePlotOptions& o) {
  const int W = std::max(320, o.width), H = std::max(240, o.height);
  cv::Mat m(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 72, right = 24, top = 44, bottom = 58;
  const int x0 = left, x1 = W - right, y0 = H - bottom, y1 = top;  // y0: bottom of the plot

  double t_max = o.t_max_s;
  if (!(t_max > 0)) {
    for (const auto& s : series) {
      for (const auto& p : s.points) t_max = std::max(t_max, p.first);
    }
  }
  if (!(t_max > 0)) t_max = 1.0;
  auto xt = nice_ticks(t_max, 8);
  double step_x = xt.size() > 1 ? xt[1] - xt[0] : t_max;
  if (xt.back() < t_max * (1 - 1e-9)) xt.push_back(xt.back() + step_x);
  const double x_axis = xt.back();
  const double y_max = o.y_max_pct > 0 ? o.y_max_pct : 100.0;
  const auto yt = nice_ticks(y_max, 10);
  const double step_y = yt.size() > 1 ? yt[1] - yt[0] : y_max;

  auto px = [&](double t) { return x0 + (x1 - x0) * std::clamp(t / x_axis, 0.0, 1.0); };
  auto py = [&](double c) { return y0 - (y0 - y1) * std::clamp(c / y_max, 0.0, 1.0); };
  const cv::Scalar grid(232, 232, 232), axis(0, 0, 0), text(30, 30, 30);

  // Grid and ticks.
  for (const double t : xt) {
    const int x = static_cast<int>(std::lround(px(t)));
    cv::line(m, {x, y0}, {x, y1}, grid, 1);
    cv::line(m, {x, y0}, {x, y0 + 5}, axis, 1);
    draw::text_centered(m, tick_label(t, step_x), {x, y0 + 20}, 0.45, text);
  }
  for (const double c : yt) {
    const int y = static_cast<int>(std::lround(py(c)));
    cv::line(m, {x0, y}, {x1, y}, grid, 1);
    cv::line(m, {x0 - 5, y}, {x0, y}, axis, 1);
    draw::text_right(m, tick_label(c, step_y), {x0 - 8, y + 5}, 0.45, text);
  }
  // Threshold.
  if (o.threshold_pct > 0 && o.threshold_pct <= y_max) {
    const int y = static_cast<int>(std::lround(py(o.threshold_pct)));
    draw::dashed_line(m, {x0, y}, {x1, y}, cv::Scalar(40, 40, 200), 1, 8, 6);
    char b[32];
    std::snprintf(b, sizeof b, "%g %%", o.threshold_pct);
    draw::text_right(m, b, {x1 - 4, y - 6}, 0.45, cv::Scalar(40, 40, 200));
  }
  // Bands first, each blended on its own so that overlapping bands stay visible, under every curve.
  for (size_t i = 0; i < series.size(); ++i) {
    const auto& s = series[i];
    std::vector<cv::Point> poly;
    for (const auto& b : s.band) {
      if (std::isfinite(b.t) && std::isfinite(b.hi))
        poly.emplace_back(static_cast<int>(std::lround(px(b.t))), static_cast<int>(std::lround(py(b.hi))));
    }
    for (auto it = s.band.rbegin(); it != s.band.rend(); ++it) {
      if (std::isfinite(it->t) && std::isfinite(it->lo))
        poly.emplace_back(static_cast<int>(std::lround(px(it->t))),
                          static_cast<int>(std::lround(py(it->lo))));
    }
    if (poly.size() < 3) continue;
    Rgb c = s.color;
    if (c == Rgb{0, 0, 0}) c = palette(static_cast<int>(i));
    cv::Mat layer = m.clone();
    cv::fillPoly(layer, std::vector<std::vector<cv::Point>>{poly}, draw::bgr(c), cv::LINE_AA);
    cv::addWeighted(layer, 0.2, m, 0.8, 0, m);
  }
  // Series.
  for (size_t i = 0; i < series.size(); ++i) {
    const auto& s = series[i];
    Rgb c = s.color;
    if (c == Rgb{0, 0, 0}) c = palette(static_cast<int>(i));
    std::vector<cv::Point> pts;
    pts.reserve(s.points.size());
    for (const auto& p : s.points) {
      if (!std::isfinite(p.first) || !std::isfinite(p.second)) continue;
      pts.emplace_back(static_cast<int>(std::lround(px(p.first))),
                       static_cast<int>(std::lround(py(p.second))));
    }
    if (pts.size() == 1) cv::circle(m, pts[0], 2, draw::bgr(c), cv::FILLED, cv::LINE_AA);
    if (pts.size() >= 2) cv::polylines(m, pts, false, draw::bgr(c), std::max(1, s.thickness), cv::LINE_AA);
  }
  // Axes, labels, title.
  cv::line(m, {x0, y0}, {x1, y0}, axis, 1);
  cv::line(m, {x0, y0}, {x0, y1}, axis, 1);
  draw::text_centered(m, o.x_label, {(x0 + x1) / 2, H - 14}, 0.5, text);
  draw::text_vertical(m, o.y_label, {20, (y0 + y1) / 2}, 0.5, text);
  draw::text_centered(m, o.title, {W / 2, 26}, 0.6, text, 1);
  // Legend (bottom right, where coverage curves rarely are).
  std::vector<std::pair<std::string, Rgb>> entries;
  for (size_t i = 0; i < series.size(); ++i) {
    if (series[i].label.empty()) continue;
    Rgb c = series[i].color;
    if (c == Rgb{0, 0, 0}) c = palette(static_cast<int>(i));
    entries.emplace_back(series[i].label, c);
  }
  draw::legend(m, entries, {x1 - 10, y0 - 10}, draw::Corner::kBottomRight);

  return draw::to_image(m);
}

void write_coverage_plot(const std::string& path, const std::vector<PlotSeries>& series,
                         const CoveragePlotOptions& options) {
  write_png(render_coverage_plot(series, options), path);
}

}  // namespace semx::evaluator
