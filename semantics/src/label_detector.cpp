#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <unordered_map>

#include "semx/semantics/detector.hpp"

namespace semx::semantics {

using runtime::SemanticClass;

LabelDetector::LabelDetector(const DetectorConfig& config, const RegionConfig& classes) : config_(config) {
  for (std::size_t i = 1; i < kClassCount; ++i) {
    enabled_[i] = classes.classes[i].enabled && !runtime::kSemanticClasses[i].structural;
  }
}

std::vector<Detection2D> LabelDetector::detect(const Frame& frame) {
  if (!frame.has_labels() || frame.class_label.size() != frame.pixels()) return {};
  const uint16_t* inst = config_.use_instances && frame.instance_label.size() == frame.pixels()
                             ? frame.instance_label.data()
                             : nullptr;
  return detect_labels(frame.camera.width, frame.camera.height, frame.class_label.data(), inst, nullptr);
}

namespace {

struct Blob {
  uint32_t key = 0;
  int min_u = 0, min_v = 0, max_u = -1, max_v = -1;
  int count = 0;
};

}  // namespace

std::vector<Detection2D> LabelDetector::detect_labels(int width, int height, const uint16_t* classes,
                                                      const uint16_t* instances, const float* scores) {
  std::vector<Detection2D> out;
  if (width <= 0 || height <= 0 || classes == nullptr) return out;

  // Pass 1, one run of equal labels at a time: bounding box and size of every (class, instance).
  std::unordered_map<uint32_t, std::size_t> index;
  std::vector<Blob> blobs;
  for (int v = 0; v < height; ++v) {
    const uint16_t* c = classes + static_cast<std::size_t>(v) * width;
    const uint16_t* in = instances ? instances + static_cast<std::size_t>(v) * width : nullptr;
    int u = 0;
    while (u < width) {
      const uint16_t cls = c[u];
      const uint16_t id = in ? in[u] : 0;
      int end = u + 1;
      while (end < width && c[end] == cls && (!in || in[end] == id)) ++end;
      if (cls < kClassCount && enabled_[cls]) {
        const uint32_t key = cls | (static_cast<uint32_t>(id) << 16);
        auto [it, inserted] = index.emplace(key, blobs.size());
        if (inserted) {
          Blob b;
          b.key = key;
          b.min_u = u;
          b.min_v = v;
          b.max_u = end - 1;
          b.max_v = v;
          blobs.push_back(b);
        }
        Blob& b = blobs[it->second];
        b.min_u = std::min(b.min_u, u);
        b.max_u = std::max(b.max_u, end - 1);
        b.max_v = v;
        b.count += end - u;
      }
      u = end;
    }
  }
  std::sort(blobs.begin(), blobs.end(), [](const Blob& a, const Blob& b) { return a.key < b.key; });

  // Pass 2, inside each blob's box: mask, opening, connected components, minimum area.
  const int k = config_.morph_kernel_px;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k));
  cv::Mat mask, labels, stats, centroids;
  for (const Blob& b : blobs) {
    if (b.count < config_.min_area_px) continue;
    const uint16_t cls = static_cast<uint16_t>(b.key & 0xFFFF);
    const uint16_t id = static_cast<uint16_t>(b.key >> 16);
    const int bw = b.max_u - b.min_u + 1, bh = b.max_v - b.min_v + 1;
    mask.create(bh, bw, CV_8U);
    for (int y = 0; y < bh; ++y) {
      const std::size_t row = static_cast<std::size_t>(b.min_v + y) * width + b.min_u;
      uint8_t* m = mask.ptr<uint8_t>(y);
      for (int x = 0; x < bw; ++x) {
        m[x] = (classes[row + x] == cls && (!instances || instances[row + x] == id)) ? 255 : 0;
      }
    }
    if (k > 1) cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel);
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);

    // Components that survive; with instances they are parts of one object.
    std::vector<int> keep;
    for (int l = 1; l < n; ++l) {
      if (stats.at<int>(l, cv::CC_STAT_AREA) >= config_.min_area_px) keep.push_back(l);
    }
    if (keep.empty()) continue;
    std::vector<std::vector<int>> groups;
    if (instances) {
      groups.push_back(keep);
    } else {
      for (int l : keep) groups.push_back({l});
    }
    std::vector<uint8_t> in_group(static_cast<std::size_t>(n), 0);
    for (const auto& group : groups) {
      std::fill(in_group.begin(), in_group.end(), 0);
      for (int l : group) in_group[static_cast<std::size_t>(l)] = 1;
      int x0 = bw, y0 = bh, x1 = -1, y1 = -1;
      for (int l : group) {
        x0 = std::min(x0, stats.at<int>(l, cv::CC_STAT_LEFT));
        y0 = std::min(y0, stats.at<int>(l, cv::CC_STAT_TOP));
        x1 = std::max(x1, stats.at<int>(l, cv::CC_STAT_LEFT) + stats.at<int>(l, cv::CC_STAT_WIDTH) - 1);
        y1 = std::max(y1, stats.at<int>(l, cv::CC_STAT_TOP) + stats.at<int>(l, cv::CC_STAT_HEIGHT) - 1);
      }
      Detection2D d;
      d.cls = static_cast<SemanticClass>(cls);
      d.instance = id;
      d.box = {b.min_u + x0, b.min_v + y0, x1 - x0 + 1, y1 - y0 + 1};
      d.mask.assign(static_cast<std::size_t>(d.box.area()), 0);
      double score_sum = 0;
      for (int y = y0; y <= y1; ++y) {
        const int* lab = labels.ptr<int>(y);
        uint8_t* m = d.mask.data() + static_cast<std::size_t>(y - y0) * d.box.width;
        for (int x = x0; x <= x1; ++x) {
          if (!in_group[static_cast<std::size_t>(lab[x])]) continue;
          m[x - x0] = 1;
          ++d.area;
          if (scores) score_sum += scores[static_cast<std::size_t>(b.min_v + y) * width + b.min_u + x];
        }
      }
      d.score = scores && d.area > 0 ? static_cast<float>(score_sum / d.area) : 1.0f;
      out.push_back(std::move(d));
    }
  }
  return out;
}

void set_detector_threads(int threads) { cv::setNumThreads(threads); }

std::unique_ptr<Detector> make_detector(const SemanticsConfig& config) {
  if (config.detector.type == "dnn") return std::make_unique<DnnDetector>(config.detector, config.regions);
  if (config.detector.type == "labels")
    return std::make_unique<LabelDetector>(config.detector, config.regions);
  throw DetectorError("unknown detector type '" + config.detector.type + "' (known: labels, dnn)");
}

}  // namespace semx::semantics
