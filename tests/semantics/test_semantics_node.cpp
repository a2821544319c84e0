// The semantics node over memq:// (one process): camera parts paired by frame_id, content checks
// counted as malformed, SEMANTIC_REGIONS on change and every second of message time.
#include <gtest/gtest.h>

#include <limits>
#include <semx/clock_t.hpp>

#include "semantics_messages.hpp"
#include "semantics_node.hpp"
#include "semantics_test_util.hpp"
#include "semx/runtime/channels.hpp"
#include "simulator_messages.hpp"

using namespace semx::semantics;
using namespace semx::semantics::test;
namespace ch = semx::channels;
using semx::runtime::ImageCompression;

namespace {

semx::runtime::NodeOptions memq() {
  semx::runtime::NodeOptions o;
  o.name = "semantics";
  o.lcm_url = "memq://";
  o.status_period_s = 1000;
  o.quiet = true;
  return o;
}

struct Harness {
  explicit Harness(const SemanticsConfig& config = SemanticsConfig{}) : sn(memq(), config) {
    sn.node().subscribe<semx::semantic_regions_t>(
        ch::SEMANTIC_REGIONS, [this](const semx::semantic_regions_t& m) { published.push_back(m); });
  }
  SemanticsNode sn;
  Scene scene{room({Solid::box(SemanticClass::kChair, {4.0, 2.5, 0.45}, {0.45, 0.45, 0.9})})};
  std::vector<semx::semantic_regions_t> published;
  int64_t frame = 0, tick = 0, utime = 0;

  template <class T>
  void send(const char* channel, const T& m) {
    sn.node().publish(channel, m);
    sn.node().drain();
  }
  semx::simulator::CameraFrame capture() { return scene.render_raw({1.5, 2.5, 1.4}, 0.0, utime, frame++); }
  // One camera frame (depth then labels, or the other way round), then a clock tick.
  void step(bool labels_first = false) {
    utime += 33333;
    const auto f = capture();
    const auto d = semx::simulator::depth_message(f, ImageCompression::kNone);
    const auto l = semx::simulator::label_message(f, ImageCompression::kRle);
    if (labels_first) send(ch::CAMERA_LABELS, l);
    send(ch::CAMERA_DEPTH, d);
    if (!labels_first) send(ch::CAMERA_LABELS, l);
    clock(utime);
  }
  void clock(int64_t t) {
    semx::clock_t c{};
    c.tick = ++tick;
    c.utime = t;
    c.mode = semx::clock_t::REALTIME;
    c.period_us = 10000;
    send(ch::SIM_CLOCK, c);
  }
  int64_t malformed(const char* channel) const {
    const auto& in = sn.node().incoming();
    const auto it = in.find(channel);
    return it == in.end() ? 0 : it->second.malformed;
  }
};

}  // namespace

TEST(SemanticsNode, FramesInRegionsOut) {
  Harness h;
  for (int k = 0; k < 30; ++k) h.step(k % 2 == 1);
  // 30 Hz frames, detector.frame_period_s = 0.1: every third capture, the others unread.
  EXPECT_EQ(h.sn.counters().frames_processed, 10);
  EXPECT_EQ(h.sn.counters().frames_skipped, 20);
  EXPECT_EQ(h.sn.node().incoming().at(ch::CAMERA_DEPTH).skipped, 20);
  EXPECT_EQ(h.sn.node().incoming().at(ch::CAMERA_LABELS).skipped, 20);
  EXPECT_EQ(h.sn.node().incoming().at(ch::CAMERA_DEPTH).malformed, 0);
  ASSERT_FALSE(h.published.empty());
  const auto& last = h.published.back();
  ASSERT_EQ(last.num_regions, 1);
  const auto& r = last.regions[0];
  EXPECT_EQ(r.class_id, static_cast<int16_t>(SemanticClass::kChair));
  EXPECT_EQ(r.label, "chair");
  EXPECT_NEAR(r.centroid[0], 4.0, 0.15);
  EXPECT_NEAR(r.centroid[1], 2.5, 0.15);
  EXPECT_GT(r.weight, 0);
  EXPECT_GT(r.radius, 1.0);
  EXPECT_GE(r.observations, 5);
  EXPECT_TRUE(r.active);
  EXPECT_EQ(r.instance, h.scene.world().solids.back().instance);
  for (std::size_t i = 1; i < h.published.size(); ++i)
    EXPECT_EQ(h.published[i].seq, h.published[i - 1].seq + 1);
  // The round trip through the message keeps the region.
  const auto back = from_message(last);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].cls, SemanticClass::kChair);
  EXPECT_EQ(back[0].id, r.id);
}

TEST(SemanticsNode, RegionsGoOutTheDetectorsLatencyAfterTheirFrame) {
  Harness h;  // detector.latency_s = 0.05: the frame is processed after its tick's ack
  h.clock(0);
  h.step();
  EXPECT_EQ(h.sn.counters().frames_processed, 1);
  EXPECT_TRUE(h.published.empty());
  h.clock(h.utime + 40000);
  EXPECT_TRUE(h.published.empty()) << "still within the latency";
  h.clock(h.utime + 50000);
  ASSERT_EQ(h.published.size(), 1u);
  EXPECT_EQ(h.published[0].utime, h.utime + 50000);
  // Without latency the regions go out with the frame's own tick.
  SemanticsConfig c;
  c.detector.latency_s = 0;
  Harness g(c);
  g.clock(0);
  g.step();
  ASSERT_EQ(g.published.size(), 1u);
  EXPECT_EQ(g.published[0].utime, g.utime);
  // Without a clock (frames fed by hand) no tick would come: at once.
  Harness n;
  const auto f = n.capture();
  n.send(ch::CAMERA_DEPTH, semx::simulator::depth_message(f, ImageCompression::kNone));
  n.send(ch::CAMERA_LABELS, semx::simulator::label_message(f, ImageCompression::kRle));
  EXPECT_EQ(n.sn.counters().frames_processed, 1);
  EXPECT_EQ(n.published.size(), 1u);
}

TEST(SemanticsNode, RepublishesEverySecondOfMessageTimeWithoutChanges) {
  Harness h;
  for (int k = 0; k < 30; ++k) h.step();
  const std::size_t before = h.published.size();
  // 3.5 s of clock ticks and no frames: the unchanged set goes out once per second.
  for (int k = 1; k <= 350; ++k) h.clock(h.utime + k * 10000);
  EXPECT_EQ(h.published.size(), before + 3);
  EXPECT_EQ(h.published.back().num_regions, 1);
}

TEST(SemanticsNode, MalformedCameraMessagesAreCountedAndDropped) {
  Harness h;
  const auto f = h.capture();
  auto depth = semx::simulator::depth_message(f, ImageCompression::kNone);
  auto labels = semx::simulator::label_message(f, ImageCompression::kRle);

  auto short_depth = depth;  // fewer bytes than width*height*2
  short_depth.depth_data.resize(1000);
  short_depth.num_depth_bytes = 1000;
  h.send(ch::CAMERA_DEPTH, short_depth);
  auto nan_pose = depth;
  nan_pose.info.sensor_position[1] = std::numeric_limits<double>::quiet_NaN();
  h.send(ch::CAMERA_DEPTH, nan_pose);
  auto bad_quaternion = depth;
  bad_quaternion.info.sensor_orientation[0] = 3.0;
  h.send(ch::CAMERA_DEPTH, bad_quaternion);
  auto huge = depth;
  huge.info.width = 1 << 20;
  h.send(ch::CAMERA_DEPTH, huge);
  auto unknown_codec = labels;
  unknown_codec.label_compression = 9;
  h.send(ch::CAMERA_LABELS, unknown_codec);
  auto zero_fx = labels;
  zero_fx.info.fx = 0;
  h.send(ch::CAMERA_LABELS, zero_fx);
  EXPECT_EQ(h.malformed(ch::CAMERA_DEPTH), 4);
  EXPECT_EQ(h.malformed(ch::CAMERA_LABELS), 2);

  // Plausible sizes that do not decode: dropped by the node, counted as bad payloads.
  auto corrupt = labels;
  ASSERT_EQ(corrupt.label_compression, static_cast<int8_t>(ImageCompression::kRle));
  for (std::size_t i = 1; i < corrupt.label_data.size(); ++i) corrupt.label_data[i] = 0xFF;
  h.send(ch::CAMERA_LABELS, corrupt);
  EXPECT_EQ(h.sn.counters().bad_payload, 1);

  // Labels of another size under the same frame_id: the pair is dropped.
  h.send(ch::CAMERA_DEPTH, depth);
  auto other_size =
      semx::simulator::label_message(h.scene.render_raw({1.5, 2.5, 1.4}, 0.0, 0, 0), ImageCompression::kNone);
  other_size.info.frame_id = depth.info.frame_id;
  other_size.info.width = 320;
  other_size.info.cx = 160;
  other_size.label_data.resize(320 * 480 * 4);
  other_size.num_label_bytes = static_cast<int32_t>(other_size.label_data.size());
  h.send(ch::CAMERA_LABELS, other_size);
  EXPECT_EQ(h.sn.counters().parts_mismatched, 1);
  EXPECT_EQ(h.sn.counters().frames_processed, 0);
  EXPECT_TRUE(h.published.empty());

  // The node is still fine.
  for (int k = 0; k < 30; ++k) h.step();
  EXPECT_EQ(h.sn.counters().frames_processed, 10);
  ASSERT_FALSE(h.published.empty());
  EXPECT_EQ(h.published.back().num_regions, 1);
  EXPECT_EQ(h.sn.node().counters().handler_errors, 0);
}

TEST(SemanticsNode, FramePeriodZeroProcessesEveryFrame) {
  SemanticsConfig c;
  c.detector.frame_period_s = 0;
  Harness h(c);
  for (int k = 0; k < 30; ++k) h.step(k % 2 == 1);
  EXPECT_EQ(h.sn.counters().frames_processed, 30);
  EXPECT_EQ(h.sn.counters().frames_skipped, 0);
  ASSERT_FALSE(h.published.empty());
  EXPECT_EQ(h.published.back().num_regions, 1);
}

TEST(SemanticsNode, LonePartsNeverMakeAFrameAndDoNotPileUp) {
  Harness h;
  for (int k = 0; k < 20; ++k) {
    h.utime += 33333;
    h.send(ch::CAMERA_DEPTH, semx::simulator::depth_message(h.capture(), ImageCompression::kNone));
  }
  EXPECT_EQ(h.sn.counters().frames_processed, 0);
  EXPECT_EQ(h.sn.counters().frames_incomplete, 20 - static_cast<int64_t>(SemanticsNode::kMaxPending));
  EXPECT_TRUE(h.published.empty());
}

TEST(SemanticsNode, ADnnDetectorWithoutItsModelFailsAtStart) {
  SemanticsConfig c;
  c.detector.type = "dnn";
  c.detector.dnn.model = "/nonexistent/model.onnx";
  c.detector.dnn.classes = {"none", "chair"};
  EXPECT_THROW(SemanticsNode(memq(), c), DetectorError);
}
