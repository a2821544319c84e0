#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "semx/evaluator/rgb.hpp"
#include "semx/evaluator/run_folder.hpp"

namespace semx::evaluator {

Image::Image(int w, int h, Rgb fill) : width(w), height(h), rgb(static_cast<size_t>(w) * h * 3) {
  for (size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = fill.r;
    rgb[i + 1] = fill.g;
    rgb[i + 2] = fill.b;
  }
}

void write_png(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0) throw RunFolderError(path + ": empty image");
  cv::Mat bgr(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    auto* row = bgr.ptr<uint8_t>(y);
    const uint8_t* src = image.rgb.data() + 3 * static_cast<size_t>(y) * image.width;
    for (int x = 0; x < image.width; ++x) {
      row[3 * x] = src[3 * x + 2];
      row[3 * x + 1] = src[3 * x + 1];
      row[3 * x + 2] = src[3 * x];
    }
  }
  const std::string tmp = path + ".tmp.png";
  bool ok = false;
  try {
    ok = cv::imwrite(tmp, bgr);
  } catch (const cv::Exception& e) {
    throw RunFolderError(path + ": cannot write the PNG (" + e.what() + ")");
  }
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw RunFolderError(path + ": cannot write the PNG");
  }
}

Rgb palette(int i) {
  static const Rgb kColors[] = {{31, 119, 180},  {255, 127, 14}, {44, 160, 44},   {214, 39, 40},
                                {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                {188, 189, 34},  {23, 190, 207}};
  constexpr int n = sizeof(kColors) / sizeof(kColors[0]);
  return kColors[((i % n) + n) % n];
}

}  // namespace semx::evaluator
