// The optional OpenCV highgui window of semx-viewer. Built only when OpenCV's highgui is there
// (SEMX_VIEWER_HAVE_HIGHGUI); otherwise open() always says why not, and the viewer writes PNGs.
#pragma once

#include <memory>
#include <string>

#include "semx/evaluator/rgb.hpp"

namespace semx::viewer {

class FrameWindow {
 public:
  // A window titled `title`, or nullptr with `why` set: no highgui in this build, no DISPLAY
  // (nor WAYLAND_DISPLAY), or the GUI backend failed to start.
  static std::unique_ptr<FrameWindow> open(const std::string& title, std::string* why);
  ~FrameWindow();
  FrameWindow(const FrameWindow&) = delete;
  FrameWindow& operator=(const FrameWindow&) = delete;

  void show(const evaluator::Image& image);
  // Runs the GUI's events for a moment; false once the window was closed or q / Esc pressed.
  bool poll();

 private:
  explicit FrameWindow(std::string title) : title_(std::move(title)) {}
  std::string title_;
  bool shown_ = false;
};

}  // namespace semx::viewer
