// OpenCV drawing helpers shared by the plot and the map picture (private to semx_evaluator).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "semx/evaluator/rgb.hpp"

namespace semx::evaluator::draw {

inline cv::Scalar bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }

// Text with its baseline at `at.y`, centred on / ending at `at.x`.
void text_centered(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
                   int thickness = 1);
void text_right(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
                int thickness = 1);
void text_left(cv::Mat& m, const std::string& s, cv::Point at, double scale, cv::Scalar color,
               int thickness = 1);
// Text rotated 90 degrees counter-clockwise, centred on `center`.
void text_vertical(cv::Mat& m, const std::string& s, cv::Point center, double scale, cv::Scalar color);
// The size of `s` as text_left draws it; *baseline (optional): pixels below the baseline.
cv::Size text_size(const std::string& s, double scale, int thickness = 1, int* baseline = nullptr);
void dashed_line(cv::Mat& m, cv::Point a, cv::Point b, cv::Scalar color, int thickness, int dash, int gap);

enum class Corner { kTopLeft, kTopRight, kBottomLeft, kBottomRight };
// A framed box of colour swatches and texts with the given corner at `anchor`; nothing if empty.
// legend_size: the box's size (0 x 0 if empty).
cv::Size legend_size(const std::vector<std::pair<std::string, Rgb>>& entries);
void legend(cv::Mat& m, const std::vector<std::pair<std::string, Rgb>>& entries, cv::Point anchor,
            Corner corner);

Image to_image(const cv::Mat& bgr8);

}  // namespace semx::evaluator::draw
