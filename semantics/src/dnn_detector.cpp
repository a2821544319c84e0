#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <fstream>

#include "semx/semantics/detector.hpp"

namespace semx::semantics {

struct DnnDetector::Impl {
  DetectorConfig config;
  cv::dnn::Net net;
  std::vector<uint16_t> channel_class;  // output channel -> semx class id (0 = background)
  LabelDetector labels;
  std::vector<uint16_t> class_image;
  std::vector<float> score_image;

  Impl(const DetectorConfig& c, const RegionConfig& classes) : config(c), labels(c, classes) {
    // The DNN gives no instance ids: one detection per connected component.
    config.use_instances = false;
    labels = LabelDetector(config, classes);
  }

  // Runs the network; returns the 1 x C x H x W output.
  cv::Mat forward(const cv::Mat& rgb) {
    const auto& d = config.dnn;
    const cv::Mat blob =
        cv::dnn::blobFromImage(rgb, d.scale, cv::Size(d.input_width, d.input_height),
                               cv::Scalar(d.mean[0], d.mean[1], d.mean[2]), d.swap_rb, false, CV_32F);
    net.setInput(blob);
    return net.forward();
  }
};

DnnDetector::DnnDetector(const DetectorConfig& config, const RegionConfig& classes)
    : impl_(std::make_unique<Impl>(config, classes)) {
  const auto& d = config.dnn;
  if (d.model.empty()) throw DetectorError("dnn detector: no model given (detector.dnn.model)");
  if (!std::ifstream(d.model).good()) {
    throw DetectorError("dnn detector: model file '" + d.model + "' does not exist or cannot be read");
  }
  if (d.classes.empty()) throw DetectorError("dnn detector: detector.dnn.classes is empty");
  try {
    impl_->net = cv::dnn::readNetFromONNX(d.model);
  } catch (const cv::Exception& e) {
    throw DetectorError("dnn detector: cannot load '" + d.model + "': " + e.what());
  }
  if (impl_->net.empty()) throw DetectorError("dnn detector: '" + d.model + "' holds no network");
  impl_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  impl_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  for (const auto& name : d.classes) {
    impl_->channel_class.push_back(static_cast<uint16_t>(*runtime::class_from_name(name)));
  }
  // One forward pass on a blank image checks the output's shape now rather than on the first frame.
  cv::Mat out;
  try {
    out = impl_->forward(cv::Mat(d.input_height, d.input_width, CV_8UC3, cv::Scalar(0, 0, 0)));
  } catch (const cv::Exception& e) {
    throw DetectorError("dnn detector: '" + d.model + "' fails on a " + std::to_string(d.input_width) + "x" +
                        std::to_string(d.input_height) + " input: " + e.what());
  }
  if (out.dims != 4 || out.size[0] != 1 || out.size[1] != static_cast<int>(d.classes.size())) {
    throw DetectorError("dnn detector: '" + d.model + "' must output 1 x " +
                        std::to_string(d.classes.size()) +
                        " x H x W class scores (one channel per detector.dnn.classes entry)");
  }
}

DnnDetector::~DnnDetector() = default;

std::vector<Detection2D> DnnDetector::detect(const Frame& frame) {
  if (!frame.has_rgb() || frame.rgb.size() != 3 * frame.pixels()) return {};
  Impl& im = *impl_;
  const int w = frame.camera.width, h = frame.camera.height;
  const cv::Mat rgb(h, w, CV_8UC3, const_cast<uint8_t*>(frame.rgb.data()));
  cv::Mat out;
  try {
    out = im.forward(rgb);
  } catch (const cv::Exception&) {
    return {};
  }
  const int c = out.size[1], oh = out.size[2], ow = out.size[3];
  if (out.dims != 4 || c != static_cast<int>(im.channel_class.size())) return {};

  // Per output pixel: the best channel and its (softmax) score.
  cv::Mat arg(oh, ow, CV_16U), best(oh, ow, CV_32F);
  const float* data = out.ptr<float>();
  const std::size_t plane = static_cast<std::size_t>(oh) * ow;
  for (int y = 0; y < oh; ++y) {
    for (int x = 0; x < ow; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * ow + x;
      int k_best = 0;
      float v_best = data[i], sum = 0, v_max = data[i];
      for (int k = 0; k < c; ++k) {
        const float v = data[k * plane + i];
        sum += v;
        if (v > v_best) v_best = v, k_best = k;
        v_max = std::max(v_max, v);
      }
      float score = v_best;
      // Raw logits: turn into a softmax probability.
      if (std::abs(sum - 1.0f) > 1e-3f || v_max > 1.0f) {
        float z = 0;
        for (int k = 0; k < c; ++k) z += std::exp(data[k * plane + i] - v_max);
        score = 1.0f / z;
      }
      const bool keep = score >= im.config.dnn.min_score;
      arg.at<uint16_t>(y, x) = keep ? im.channel_class[static_cast<std::size_t>(k_best)] : 0;
      best.at<float>(y, x) = score;
    }
  }
  cv::Mat arg_full, best_full;
  cv::resize(arg, arg_full, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
  cv::resize(best, best_full, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
  im.class_image.assign(arg_full.ptr<uint16_t>(), arg_full.ptr<uint16_t>() + frame.pixels());
  im.score_image.assign(best_full.ptr<float>(), best_full.ptr<float>() + frame.pixels());
  return im.labels.detect_labels(w, h, im.class_image.data(), nullptr, im.score_image.data());
}

}  // namespace semx::semantics
