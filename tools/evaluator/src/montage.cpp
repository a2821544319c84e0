#include "semx/evaluator/montage.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "draw.hpp"

namespace semx::evaluator {

namespace {
constexpr int kTitleH = 24, kHeaderH = 34, kPad = 8;
}  // namespace

Montage render_montage(const std::vector<MontageTile>& tiles, const MontageOptions& o) {
  Montage out;
  std::vector<cv::Mat> pictures;
  for (const auto& t : tiles) {
    cv::Mat p;
    std::string why;
    if (!std::filesystem::is_regular_file(t.png)) {
      why = "no such file";
    } else {
      try {
        p = cv::imread(t.png, cv::IMREAD_COLOR);
      } catch (const cv::Exception&) {
        p.release();
      }
      if (p.empty()) why = "not a readable picture";
    }
    if (!why.empty()) out.missing.push_back(t.png + ": " + why);
    pictures.push_back(p);
  }
  const int n = static_cast<int>(tiles.size());
  const int cols = std::clamp(std::min(o.columns, n), 1, std::max(1, n));
  const int rows = std::max(1, (n + cols - 1) / cols);
  const int tw = std::max(64, o.tile_width);
  int th = tw * 3 / 4;
  for (const auto& p : pictures) {
    if (p.empty()) continue;
    th = std::max(32, static_cast<int>(std::lround(tw * static_cast<double>(p.rows) / p.cols)));
    break;
  }
  const int W = kPad + cols * (tw + kPad);
  const int H = kHeaderH + rows * (kTitleH + th + kPad) + kPad;
  cv::Mat m(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  draw::text_left(m, o.title, {kPad, kHeaderH - 12}, 0.6, cv::Scalar(20, 20, 20));
  for (int i = 0; i < n; ++i) {
    const int x = kPad + (i % cols) * (tw + kPad);
    const int y = kHeaderH + (i / cols) * (kTitleH + th + kPad);
    draw::text_left(m, tiles[static_cast<size_t>(i)].title, {x, y + kTitleH - 7}, 0.48,
                    cv::Scalar(20, 20, 20));
    const cv::Rect box(x, y + kTitleH, tw, th);
    const cv::Mat& p = pictures[static_cast<size_t>(i)];
    if (p.empty()) {
      m(box).setTo(cv::Scalar(225, 225, 225));
      // The run folder's name says whose picture is missing (every tile's file is map.png).
      const std::filesystem::path f(tiles[static_cast<size_t>(i)].png);
      draw::text_centered(m, "no picture: " + (f.parent_path().filename() / f.filename()).string(),
                          {x + tw / 2, y + kTitleH + th / 2}, 0.5, cv::Scalar(40, 40, 40));
    } else {
      // Fit inside the tile, aspect kept, centred; INTER_AREA keeps thin lines from aliasing away.
      const double s = std::min(static_cast<double>(tw) / p.cols, static_cast<double>(th) / p.rows);
      const int w = std::max(1, static_cast<int>(std::lround(p.cols * s)));
      const int h = std::max(1, static_cast<int>(std::lround(p.rows * s)));
      cv::Mat scaled;
      cv::resize(p, scaled, {w, h}, 0, 0, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
      scaled.copyTo(m(cv::Rect(x + (tw - w) / 2, y + kTitleH + (th - h) / 2, w, h)));
    }
    cv::rectangle(m, box, cv::Scalar(160, 160, 160), 1);
  }
  out.image = draw::to_image(m);
  return out;
}

}  // namespace semx::evaluator
