#include "semx/simulator/sensor_noise.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/runtime/semantic_classes.hpp"

namespace semx::simulator {

void load(runtime::ConfigMap& m, DepthNoiseConfig& c) {
  m.get("enabled", c.enabled);
  m.get("sigma_0", c.sigma_0, 0.0, 1.0);
  m.get("sigma_2", c.sigma_2, 0.0, 1.0);
  m.get("dropout", c.dropout, 0.0, 1.0);
}

void load(runtime::ConfigMap& m, DetectionNoiseConfig& c) {
  m.get("enabled", c.enabled);
  m.get("miss_probability", c.miss_probability, 0.0, 1.0);
  m.get("confusion_probability", c.confusion_probability, 0.0, 1.0);
  m.get("spurious_rate", c.spurious_rate, 0.0, 20.0);
  m.get("spurious_min_radius", c.spurious_min_radius, 1, 1000);
  m.get("spurious_max_radius", c.spurious_max_radius, 1, 1000);
  if (c.spurious_max_radius < c.spurious_min_radius) {
    m.fail("spurious_max_radius", "must be at least spurious_min_radius");
  }
}

void apply_depth_noise(Image<uint16_t>& depth, const DepthNoiseConfig& config, uint64_t seed) {
  if (!config.enabled) return;
  core::XoshiroRng rng(seed);
  for (auto& d : depth.data) {
    if (d == runtime::kDepthInvalid || d == runtime::kDepthNoReturn) continue;
    if (config.dropout > 0 && rng.bernoulli(config.dropout)) {
      d = runtime::kDepthInvalid;
      continue;
    }
    const double z = d * 1e-3;
    const double sigma = config.sigma_0 + config.sigma_2 * z * z;
    const long mm = std::lround((z + sigma * rng.normal()) * 1000.0);
    // Noise must not forge a reserved value.
    d = static_cast<uint16_t>(std::clamp(mm, 1L, static_cast<long>(runtime::kDepthMaxEncodable)));
  }
}

namespace {
std::vector<uint16_t> object_classes() {
  std::vector<uint16_t> out;
  for (const auto& info : runtime::kSemanticClasses) {
    if (!info.structural) out.push_back(static_cast<uint16_t>(info.id));
  }
  return out;
}
}  // namespace

void apply_detection_noise(CameraFrame& frame, const DetectionNoiseConfig& config, uint64_t seed) {
  if (!config.enabled || frame.class_label.empty()) return;
  static const std::vector<uint16_t> kObjects = object_classes();
  core::XoshiroRng rng(seed);
  auto& cls = frame.class_label.data;
  auto& inst = frame.instance_label.data;

  // Decisions per visible object, drawn in instance order so they depend only on the seed.
  struct Fate {
    bool miss = false;
    uint16_t cls = 0;
  };
  std::map<uint16_t, Fate> fates;
  for (size_t i = 0; i < cls.size(); ++i) {
    if (cls[i] != 0 && !runtime::class_info(static_cast<runtime::SemanticClass>(cls[i])).structural) {
      fates.emplace(inst[i], Fate{false, cls[i]});
    }
  }
  for (auto& [id, fate] : fates) {
    if (rng.bernoulli(config.miss_probability)) {
      fate.miss = true;
    } else if (rng.bernoulli(config.confusion_probability)) {
      uint16_t other = fate.cls;
      while (other == fate.cls && kObjects.size() > 1)
        other = kObjects[rng.uniform_int(0, kObjects.size() - 1)];
      fate.cls = other;
    }
  }
  if (!fates.empty()) {
    for (size_t i = 0; i < cls.size(); ++i) {
      if (cls[i] == 0 || runtime::class_info(static_cast<runtime::SemanticClass>(cls[i])).structural)
        continue;
      const Fate& f = fates[inst[i]];
      cls[i] = f.miss ? 0 : f.cls;
      inst[i] = f.miss ? 0 : inst[i];
    }
  }

  const int blobs = rng.poisson(config.spurious_rate);
  const int w = frame.class_label.width, h = frame.class_label.height;
  for (int k = 0; k < blobs; ++k) {
    const int cu = rng.uniform_int(0, w - 1), cv = rng.uniform_int(0, h - 1);
    const int r = rng.uniform_int(config.spurious_min_radius, config.spurious_max_radius);
    const uint16_t c = kObjects[rng.uniform_int(0, kObjects.size() - 1)];
    const uint16_t id = static_cast<uint16_t>(kSpuriousInstanceBase + k);
    for (int v = std::max(0, cv - r); v <= std::min(h - 1, cv + r); ++v) {
      for (int u = std::max(0, cu - r); u <= std::min(w - 1, cu + r); ++u) {
        if ((u - cu) * (u - cu) + (v - cv) * (v - cv) > r * r) continue;
        // Only where the camera sees a surface: a detection needs something to back-project to.
        const size_t i = static_cast<size_t>(v) * w + u;
        if (cls[i] == 0 && inst[i] == 0) continue;
        cls[i] = c;
        inst[i] = id;
      }
    }
  }
}

}  // namespace semx::simulator
