// Stage 1, masking: label images into detections (classes, instances, clean-up, minimum area),
// and the DNN detector's errors.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>

#include "semantics_test_util.hpp"
#include "semx/semantics/detector.hpp"

using namespace semx::semantics;
using namespace semx::semantics::test;

namespace {

LabelDetector detector(bool instances = true, int min_area = 80) {
  DetectorConfig d;
  d.use_instances = instances;
  d.min_area_px = min_area;
  return LabelDetector(d, RegionConfig{});
}

const Detection2D* find(const std::vector<Detection2D>& ds, SemanticClass c, uint16_t instance = 0) {
  for (const auto& d : ds) {
    if (d.cls == c && (instance == 0 || d.instance == instance)) return &d;
  }
  return nullptr;
}

}  // namespace

TEST(LabelDetector, OneDetectionPerObjectWithItsMaskAndBox) {
  Frame f = blank_frame();
  paint(f, 100, 50, 40, 30, SemanticClass::kChair, 3, 2000);
  paint(f, 300, 200, 60, 50, SemanticClass::kTable, 4, 2500);
  paint(f, 0, 400, 640, 80, SemanticClass::kFloor, 1, 1500);  // structural: never a detection
  auto det = detector();
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 2u);
  const Detection2D* chair = find(ds, SemanticClass::kChair);
  ASSERT_NE(chair, nullptr);
  EXPECT_EQ(chair->instance, 3);
  EXPECT_EQ(chair->area, 40 * 30);
  EXPECT_EQ(chair->box.x, 100);
  EXPECT_EQ(chair->box.y, 50);
  EXPECT_EQ(chair->box.width, 40);
  EXPECT_EQ(chair->box.height, 30);
  EXPECT_TRUE(chair->at(100, 50));
  EXPECT_TRUE(chair->at(139, 79));
  EXPECT_FLOAT_EQ(chair->score, 1.0f);
  const Detection2D* table = find(ds, SemanticClass::kTable);
  ASSERT_NE(table, nullptr);
  EXPECT_EQ(table->area, 60 * 50);
}

TEST(LabelDetector, OpeningRemovesSpecklesAndSliversAndSmallBlobsAreDropped) {
  Frame f = blank_frame();
  paint(f, 200, 200, 30, 30, SemanticClass::kSofa, 5, 2000);
  // Speckles of the same instance around it, and a one-pixel line touching it.
  for (int k = 0; k < 40; ++k)
    paint(f, 150 + 7 * k % 120, 150 + 13 * k % 40, 1, 1, SemanticClass::kSofa, 5, 2000);
  paint(f, 230, 215, 100, 1, SemanticClass::kSofa, 5, 2000);
  // A 6x6 blob of another object: below the minimum area.
  paint(f, 500, 100, 6, 6, SemanticClass::kPlant, 6, 2000);
  auto det = detector();
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].cls, SemanticClass::kSofa);
  EXPECT_EQ(ds[0].area, 30 * 30);  // exactly the square: speckles and the sliver are gone
  EXPECT_EQ(ds[0].box.width, 30);
}

TEST(LabelDetector, InstancesSplitTouchingObjectsAndJoinOccludedParts) {
  Frame f = blank_frame();
  // Two chairs side by side (touching), and a table cut in two by a lamp in front of it.
  paint(f, 100, 100, 40, 60, SemanticClass::kChair, 7, 2000);
  paint(f, 140, 100, 40, 60, SemanticClass::kChair, 8, 2100);
  paint(f, 300, 300, 200, 40, SemanticClass::kTable, 9, 3000);
  paint(f, 390, 280, 20, 100, SemanticClass::kLamp, 10, 2000);
  {
    auto det = detector(true);
    const auto ds = det.detect(f);
    ASSERT_EQ(ds.size(), 4u);
    ASSERT_NE(find(ds, SemanticClass::kChair, 7), nullptr);
    ASSERT_NE(find(ds, SemanticClass::kChair, 8), nullptr);
    const Detection2D* table = find(ds, SemanticClass::kTable);
    ASSERT_NE(table, nullptr);
    EXPECT_EQ(table->area, 180 * 40);  // both visible parts, one object
    EXPECT_EQ(table->box.width, 200);
  }
  {
    // A semantic-only segmentation: one detection per connected component.
    auto det = detector(false);
    const auto ds = det.detect(f);
    int chairs = 0, tables = 0;
    for (const auto& d : ds) {
      chairs += d.cls == SemanticClass::kChair;
      tables += d.cls == SemanticClass::kTable;
      EXPECT_EQ(d.instance, 0);
    }
    EXPECT_EQ(chairs, 1);  // touching chairs are one component
    EXPECT_EQ(tables, 2);  // the table's two visible parts are two
  }
}

TEST(LabelDetector, DisabledClassesAndUnknownIdsAreIgnored) {
  Frame f = blank_frame();
  paint(f, 10, 10, 50, 50, SemanticClass::kLamp, 1, 2000);
  paint(f, 100, 10, 50, 50, SemanticClass::kTv, 2, 2000);
  for (int i = 0; i < 5000; ++i) f.class_label[50000 + i] = 777;  // no such class
  RegionConfig classes;
  classes.classes[static_cast<std::size_t>(SemanticClass::kLamp)].enabled = false;
  LabelDetector det(DetectorConfig{}, classes);
  const auto ds = det.detect(f);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].cls, SemanticClass::kTv);
}

TEST(LabelDetector, FramesWithoutLabelsOrObjectsGiveNothing) {
  auto det = detector();
  Frame f = blank_frame();
  EXPECT_TRUE(det.detect(f).empty());
  f.class_label.clear();
  f.instance_label.clear();
  EXPECT_TRUE(det.detect(f).empty());
  Frame wrong = blank_frame();
  wrong.class_label.resize(100);  // inconsistent: ignored, not read out of bounds
  EXPECT_TRUE(det.detect(wrong).empty());
}

TEST(LabelDetector, EveryObjectOfARenderedRoomIsDetected) {
  Scene scene(room({Solid::box(SemanticClass::kCabinet, {4.0, 2.5, 0.45}, {0.5, 1.0, 0.9}),
                    Solid::box(SemanticClass::kChair, {3.0, 1.5, 0.45}, {0.45, 0.45, 0.9}),
                    Solid::cylinder(SemanticClass::kPlant, {3.5, 3.6, 0.6}, 0.25, 1.2)}));
  const Frame f = scene.render({1.0, 2.5, 1.4}, 0.0);
  auto det = detector();
  const auto ds = det.detect(f);
  EXPECT_NE(find(ds, SemanticClass::kCabinet), nullptr);
  EXPECT_NE(find(ds, SemanticClass::kChair), nullptr);
  EXPECT_NE(find(ds, SemanticClass::kPlant), nullptr);
  EXPECT_EQ(ds.size(), 3u);
}

TEST(DnnDetector, AMissingModelIsAClearError) {
  SemanticsConfig c;
  c.detector.type = "dnn";
  c.detector.dnn.model = "/nonexistent/segmenter.onnx";
  c.detector.dnn.classes = {"none", "chair"};
  try {
    make_detector(c);
    FAIL() << "no error for a missing model";
  } catch (const DetectorError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/segmenter.onnx"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(DnnDetector, AFileThatIsNoModelIsAClearError) {
  const std::string path = ::testing::TempDir() + "/not_a_model.onnx";
  std::ofstream(path) << "this is not an ONNX protobuf";
  SemanticsConfig c;
  c.detector.type = "dnn";
  c.detector.dnn.model = path;
  c.detector.dnn.classes = {"none", "chair"};
  EXPECT_THROW(make_detector(c), DetectorError);
  std::remove(path.c_str());
}

// ---- a real network through the DNN detector ----

namespace {

// Minimal protobuf writer: enough for a hand-made ONNX model.
struct Pb {
  std::string b;
  void varint(uint64_t v) {
    while (v >= 0x80) {
      b.push_back(static_cast<char>((v & 0x7F) | 0x80));
      v >>= 7;
    }
    b.push_back(static_cast<char>(v));
  }
  Pb& integer(int field, uint64_t v) {
    varint(static_cast<uint64_t>(field) << 3);
    varint(v);
    return *this;
  }
  Pb& bytes(int field, const std::string& s) {
    varint(static_cast<uint64_t>(field) << 3 | 2);
    varint(s.size());
    b += s;
    return *this;
  }
  Pb& msg(int field, const Pb& m) { return bytes(field, m.b); }
};

// A 4D float tensor type [1, c, h, w].
Pb tensor_type(int c, int h, int w) {
  Pb shape;
  for (int d : {1, c, h, w}) shape.msg(1, Pb().integer(1, static_cast<uint64_t>(d)));
  Pb tensor;
  tensor.integer(1, 1).msg(2, shape);  // elem_type FLOAT, shape
  return Pb().msg(1, tensor);          // TypeProto.tensor_type
}

// ONNX model: y = Conv1x1(x, weights), x: 1x3xHxW, y: 1xCxHxW (opset 11).
void write_segmenter(const std::string& path, const std::vector<std::array<float, 3>>& weights, int h,
                     int w) {
  const int c = static_cast<int>(weights.size());
  Pb init;
  for (int d : {c, 3, 1, 1}) init.integer(1, static_cast<uint64_t>(d));
  init.integer(2, 1);  // FLOAT
  std::string raw;
  for (const auto& row : weights) raw.append(reinterpret_cast<const char*>(row.data()), sizeof(float) * 3);
  init.bytes(8, "w").bytes(9, raw);  // name, raw_data
  Pb kernel;
  kernel.bytes(1, "kernel_shape").integer(8, 1).integer(8, 1).integer(20, 7);  // ints [1, 1], type INTS
  Pb node;
  node.bytes(1, "x").bytes(1, "w").bytes(2, "y").bytes(3, "conv").bytes(4, "Conv").msg(5, kernel);
  Pb graph;
  graph.msg(1, node).bytes(2, "segmenter").msg(5, init);
  graph.msg(11, Pb().bytes(1, "x").msg(2, tensor_type(3, h, w)));
  graph.msg(12, Pb().bytes(1, "y").msg(2, tensor_type(c, h, w)));
  Pb model;
  model.integer(1, 7).msg(8, Pb().bytes(1, "").integer(2, 11)).msg(7, graph);
  std::ofstream(path, std::ios::binary) << model.b;
}

}  // namespace

TEST(DnnDetector, SegmentsWithAnOnnxNetwork) {
  // Channel 1 (chair) answers red, channel 2 (table) green; black is background.
  const std::string path = ::testing::TempDir() + "/segmenter.onnx";
  write_segmenter(path, {{0, 0, 0}, {20, 0, 0}, {0, 20, 0}}, 240, 320);
  SemanticsConfig c;
  c.detector.type = "dnn";
  c.detector.dnn.model = path;
  c.detector.dnn.classes = {"none", "chair", "table"};
  auto det = make_detector(c);
  EXPECT_EQ(det->name(), "dnn");
  EXPECT_TRUE(det->needs_rgb());
  Frame f = blank_frame();
  f.rgb.assign(3 * f.pixels(), 0);
  auto fill = [&](int x, int y, int w, int h, uint8_t r, uint8_t g) {
    for (int v = y; v < y + h; ++v) {
      for (int u = x; u < x + w; ++u) {
        f.rgb[3 * (static_cast<std::size_t>(v) * 640 + u)] = r;
        f.rgb[3 * (static_cast<std::size_t>(v) * 640 + u) + 1] = g;
      }
    }
  };
  fill(100, 100, 80, 60, 255, 0);
  fill(400, 300, 120, 100, 0, 255);
  const auto ds = det->detect(f);
  ASSERT_EQ(ds.size(), 2u);
  const Detection2D* chair = find(ds, SemanticClass::kChair);
  const Detection2D* table = find(ds, SemanticClass::kTable);
  ASSERT_NE(chair, nullptr);
  ASSERT_NE(table, nullptr);
  EXPECT_NEAR(chair->area, 80 * 60, 2 * (80 + 60));  // within a pixel of the edges (2x resampling)
  EXPECT_NEAR(table->box.x, 400, 2);
  EXPECT_GT(chair->score, 0.99f);
  EXPECT_EQ(chair->instance, 0);
  Frame no_rgb = blank_frame();
  EXPECT_TRUE(det->detect(no_rgb).empty());
  std::remove(path.c_str());
}
