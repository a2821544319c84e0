#include "frame_window.hpp"

#include <cstdlib>

#ifdef SEMX_VIEWER_HAVE_HIGHGUI
#include <opencv2/core.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace semx::viewer {

#ifdef SEMX_VIEWER_HAVE_HIGHGUI

std::unique_ptr<FrameWindow> FrameWindow::open(const std::string& title, std::string* why) {
  const char* x = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  if ((!x || !*x) && (!w || !*w)) {
    if (why) *why = "no display (DISPLAY is not set)";
    return nullptr;
  }
  try {
    cv::namedWindow(title, cv::WINDOW_AUTOSIZE);
  } catch (const cv::Exception& e) {
    if (why) *why = std::string("the OpenCV GUI did not start: ") + e.what();
    return nullptr;
  }
  return std::unique_ptr<FrameWindow>(new FrameWindow(title));
}

FrameWindow::~FrameWindow() {
  try {
    cv::destroyWindow(title_);
  } catch (const cv::Exception&) {
    // Already gone (closed by the user): nothing to clean up.
  }
}

void FrameWindow::show(const evaluator::Image& image) {
  if (image.width <= 0 || image.height <= 0) return;
  // Image is RGB; highgui wants BGR.
  cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::imshow(title_, bgr);
  shown_ = true;
}

bool FrameWindow::poll() {
  const int key = cv::waitKey(1);
  if (key == 'q' || key == 27) return false;
  try {
    // Closing the window with its button leaves it invisible; only ask once it was shown.
    if (shown_ && cv::getWindowProperty(title_, cv::WND_PROP_VISIBLE) < 1) return false;
  } catch (const cv::Exception&) {
    return false;
  }
  return true;
}

#else

std::unique_ptr<FrameWindow> FrameWindow::open(const std::string&, std::string* why) {
  if (why) *why = "this build has no OpenCV highgui";
  return nullptr;
}
FrameWindow::~FrameWindow() = default;
void FrameWindow::show(const evaluator::Image&) {}
bool FrameWindow::poll() { return false; }

#endif

}  // namespace semx::viewer
