#include "semx/semantics/config.hpp"

#include <string>

namespace semx::semantics {

using runtime::SemanticClass;

std::array<ClassParams, kClassCount> RegionConfig::default_classes() {
  std::array<ClassParams, kClassCount> c{};  // structural classes: disabled, weight 0
  auto set = [&](SemanticClass cls, double weight, double radius) {
    c[static_cast<std::size_t>(cls)] = ClassParams{true, weight, radius};
  };
  // Doors lead into unexplored rooms: the highest weight and the widest radius.
  set(SemanticClass::kDoor, 3.0, 2.0);
  set(SemanticClass::kChair, 1.0, 1.0);
  set(SemanticClass::kTable, 1.0, 1.2);
  set(SemanticClass::kSofa, 1.0, 1.5);
  set(SemanticClass::kBed, 1.0, 1.5);
  set(SemanticClass::kCabinet, 1.0, 1.0);
  set(SemanticClass::kShelf, 1.5, 1.2);
  set(SemanticClass::kTv, 2.0, 1.5);
  set(SemanticClass::kPlant, 1.0, 1.0);
  set(SemanticClass::kLamp, 0.5, 0.8);
  set(SemanticClass::kDesk, 1.0, 1.2);
  set(SemanticClass::kToilet, 1.5, 1.2);
  set(SemanticClass::kSink, 1.5, 1.0);
  set(SemanticClass::kRefrigerator, 2.0, 1.5);
  set(SemanticClass::kBathtub, 1.5, 1.5);
  return c;
}

namespace {

void load_dnn(runtime::ConfigMap& m, DnnConfig& c) {
  m.get("model", c.model);
  m.get("input_width", c.input_width, 8, 4096);
  m.get("input_height", c.input_height, 8, 4096);
  m.get("scale", c.scale, 0.0, 1e6);
  m.get("mean", c.mean);
  if (c.mean.size() != 3) m.fail("mean", "expected a list of 3 numbers [r, g, b]");
  m.get("swap_rb", c.swap_rb);
  m.get("classes", c.classes);
  for (const auto& name : c.classes) {
    if (!runtime::class_from_name(name)) m.fail("classes", "unknown class '" + name + "'");
  }
  m.get("min_score", c.min_score, 0.0, 1.0);
}

}  // namespace

void load(runtime::ConfigMap& m, SemanticsConfig& c) {
  auto d = m.child("detector");
  d.get_choice("type", c.detector.type, {"labels", "dnn"});
  d.get("use_instances", c.detector.use_instances);
  d.get("min_area_px", c.detector.min_area_px, 1, 1 << 24);
  d.get("morph_kernel_px", c.detector.morph_kernel_px, 1, 31);
  if (c.detector.morph_kernel_px % 2 == 0) d.fail("morph_kernel_px", "must be odd");
  d.get("frame_period_s", c.detector.frame_period_s, 0.0, 3600.0);
  d.get("latency_s", c.detector.latency_s, 0.0, 10.0);
  auto dnn = d.child("dnn");
  load_dnn(dnn, c.detector.dnn);
  if (c.detector.type == "dnn" && c.detector.dnn.model.empty()) {
    dnn.fail("model", "detector.type is dnn: give the path of an ONNX model");
  }

  auto l = m.child("lift");
  l.get("max_pixel_stride", c.lift.max_pixel_stride, 1, 64);
  l.get("voxel_size", c.lift.voxel_size, 0.005, 1.0);
  l.get("outlier_neighbours", c.lift.outlier_neighbours, 0, 100);
  l.get("outlier_stddev", c.lift.outlier_stddev, 0.1, 100.0);
  l.get("cluster_tolerance", c.lift.cluster_tolerance, 0.005, 5.0);
  l.get("min_points", c.lift.min_points, 1, 1000000);
  if (c.lift.cluster_tolerance < c.lift.voxel_size) {
    l.fail("cluster_tolerance", "must be at least voxel_size (neighbouring voxels would not connect)");
  }

  auto t = m.child("tracking");
  t.get("gate_distance", c.tracking.gate_distance, 0.0, 10.0);
  t.get("min_observations", c.tracking.min_observations, 1, 100000);
  t.get("min_duration_s", c.tracking.min_duration_s, 0.0, 3600.0);
  t.get("promote_probability", c.tracking.promote_probability, 0.0, 1.0);
  t.get("log_odds_hit", c.tracking.log_odds_hit, 0.0, 10.0);
  t.get("log_odds_miss", c.tracking.log_odds_miss, 0.0, 10.0);
  t.get("region_log_odds_miss", c.tracking.region_log_odds_miss, 0.0, 10.0);
  t.get("log_odds_max", c.tracking.log_odds_max, 0.0, 100.0);
  t.get("drop_log_odds", c.tracking.drop_log_odds, -100.0, 0.0);
  t.get("tentative_timeout_s", c.tracking.tentative_timeout_s, 0.0, 3600.0);
  t.get("voxel_min_observations", c.tracking.voxel_min_observations, 1, 1000);
  t.get("voxel_min_fraction", c.tracking.voxel_min_fraction, 0.0, 1.0);
  t.get("merge_overlap", c.tracking.merge_overlap, 0.0, 1.0);
  t.get("confusion_ratio", c.tracking.confusion_ratio, 0.0, 1e6);
  t.get("face_cell", c.tracking.face_cell, 0.01, 1.0);
  t.get("free_probe", c.tracking.free_probe, 0.0, 1.0);
  t.get("fully_observed_fraction", c.tracking.fully_observed_fraction, 0.0, 1.0);
  t.get("min_known_fraction", c.tracking.min_known_fraction, 0.0, 1.0);

  auto r = m.child("regions");
  r.get("weight_scale", c.regions.weight_scale, 0.0, 1e9);
  r.get("radius_extent_gain", c.regions.radius_extent_gain, 0.0, 100.0);
  r.get("publish_period_s", c.regions.publish_period_s, 0.01, 3600.0);
  r.get("change_distance", c.regions.change_distance, 0.0, 100.0);
  r.get("change_fraction", c.regions.change_fraction, 0.0, 1.0);
  auto classes = r.child("classes");
  for (std::size_t i = 1; i < kClassCount; ++i) {
    const auto& info = runtime::kSemanticClasses[i];
    const std::string name(info.name);
    if (!classes.has(name)) continue;
    auto k = classes.child(name);
    ClassParams& p = c.regions.classes[i];
    k.get("enabled", p.enabled);
    if (p.enabled && info.structural)
      k.fail("enabled", "'" + name + "' is part of the building, not an object");
    k.get("weight", p.weight, 0.0, 1e9);
    k.get("radius", p.radius, 0.0, 1000.0);
    if (p.enabled && !(p.radius > 0 || c.regions.radius_extent_gain > 0)) {
      k.fail("radius", "an enabled class needs a positive radius");
    }
  }
}

}  // namespace semx::semantics
