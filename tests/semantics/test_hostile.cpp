// Hostile input to the library: wrong image sizes, empty frames, NaN and non-rotation poses,
// absurd intrinsics, time going backwards. Nothing crashes; bad frames are refused and counted.
#include <gtest/gtest.h>

#include <limits>

#include "semantics_test_util.hpp"
#include "semx/semantics/pipeline.hpp"

using namespace semx::semantics;
using namespace semx::semantics::test;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Frame good() {
  Frame f = blank_frame();
  paint(f, 200, 150, 120, 160, SemanticClass::kChair, 1, 2000);
  return f;
}
}  // namespace

TEST(Hostile, ValidateNamesWhatIsWrong) {
  EXPECT_EQ(validate(good()), "");
  struct Case {
    const char* what;
    std::function<void(Frame&)> spoil;
    const char* needle;
  };
  const Case cases[] = {
      {"short depth", [](Frame& f) { f.depth.resize(100); }, "depth"},
      {"no depth", [](Frame& f) { f.depth.clear(); }, "depth"},
      {"long labels", [](Frame& f) { f.class_label.push_back(1); }, "class labels"},
      {"short instances", [](Frame& f) { f.instance_label.pop_back(); }, "instance"},
      {"instances alone", [](Frame& f) { f.class_label.clear(); }, "instance"},
      {"rgb size", [](Frame& f) { f.rgb.assign(10, 0); }, "rgb"},
      {"zero width", [](Frame& f) { f.camera.width = 0; }, "size"},
      {"huge", [](Frame& f) { f.camera.width = 100000; }, "size"},
      {"negative height", [](Frame& f) { f.camera.height = -480; }, "size"},
      {"nan fx", [](Frame& f) { f.camera.fx = kNaN; }, "intrinsics"},
      {"zero fy", [](Frame& f) { f.camera.fy = 0; }, "intrinsics"},
      {"inf cx", [](Frame& f) { f.camera.cx = std::numeric_limits<double>::infinity(); }, "intrinsics"},
      {"inverted range", [](Frame& f) { f.camera.min_range = 6; }, "range"},
      {"nan range", [](Frame& f) { f.camera.max_range = kNaN; }, "range"},
      {"nan position", [](Frame& f) { f.pose.translation().x() = kNaN; }, "pose"},
      {"nan rotation", [](Frame& f) { f.pose.linear()(1, 2) = kNaN; }, "pose"},
      {"scaled rotation", [](Frame& f) { f.pose.linear() *= 2.0; }, "rotation"},
      {"reflection", [](Frame& f) { f.pose.linear().col(0) *= -1.0; }, "rotation"},
  };
  for (const auto& c : cases) {
    Frame f = good();
    c.spoil(f);
    const std::string why = validate(f);
    EXPECT_NE(why.find(c.needle), std::string::npos) << c.what << ": '" << why << "'";
  }
}

TEST(Hostile, ThePipelineRefusesBadFramesAndKeepsGoing) {
  SemanticPipeline sem{SemanticsConfig{}};
  int64_t t = 0;
  auto feed = [&](Frame f) {
    f.utime = (t += 33333);
    return sem.process(f);
  };
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(feed(good()).accepted);
  Frame nan_pose = good();
  nan_pose.pose.translation().y() = kNaN;
  EXPECT_FALSE(feed(nan_pose).accepted);
  Frame small = good();
  small.depth.resize(320 * 240);
  EXPECT_FALSE(feed(small).accepted);
  Frame no_labels = good();
  no_labels.class_label.clear();
  no_labels.instance_label.clear();
  const FrameStats s = feed(no_labels);
  EXPECT_FALSE(s.accepted);
  EXPECT_NE(s.reject_reason.find("label"), std::string::npos);
  EXPECT_EQ(sem.counters().rejected, 3);
  // The refused frames changed nothing: the chair's track carries on.
  for (int k = 0; k < 15; ++k) EXPECT_TRUE(feed(good()).accepted);
  ASSERT_EQ(sem.regions().size(), 1u);
  EXPECT_EQ(sem.regions()[0].observations, 20);
}

TEST(Hostile, EmptyAndDegenerateFramesAreHarmless) {
  SemanticPipeline sem{SemanticsConfig{}};
  Frame empty = blank_frame();  // nothing in view
  EXPECT_TRUE(sem.process(empty).accepted);
  EXPECT_EQ(sem.process(empty).detections_2d, 0);
  // Labels everywhere but no depth anywhere.
  Frame blind = good();
  for (auto& d : blind.depth) d = semx::runtime::kDepthInvalid;
  const FrameStats s = sem.process(blind);
  EXPECT_EQ(s.detections_2d, 1);
  EXPECT_EQ(s.detections_3d, 0);
  EXPECT_EQ(s.lift_no_depth, 1);
  // A 1x1 image, and one full of garbage class ids.
  Frame tiny = blank_frame(1, 1);
  tiny.class_label[0] = 5;
  EXPECT_TRUE(sem.process(tiny).accepted);
  Frame garbage = blank_frame();
  for (std::size_t i = 0; i < garbage.class_label.size(); ++i) {
    garbage.class_label[i] = static_cast<uint16_t>(i * 2654435761u);
    garbage.instance_label[i] = static_cast<uint16_t>(i * 40503u);
    garbage.depth[i] = static_cast<uint16_t>(i * 7919u);
  }
  EXPECT_TRUE(sem.process(garbage).accepted);
  EXPECT_TRUE(sem.regions().empty());
}

TEST(Hostile, TimeGoingBackwardsStartsANewEpisode) {
  SemanticPipeline sem{SemanticsConfig{}};
  for (int k = 0; k < 20; ++k) {
    Frame f = good();
    f.utime = 10'000'000 + k * 33333;
    sem.process(f);
  }
  ASSERT_EQ(sem.regions().size(), 1u);
  Frame f = good();
  f.utime = 0;
  sem.process(f);
  EXPECT_EQ(sem.counters().episodes, 1);
  EXPECT_TRUE(sem.regions().empty());
  EXPECT_EQ(sem.tracker().tracks().size(), 1u);  // the new episode's first observation
}
