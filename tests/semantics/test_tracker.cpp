// Stage 3: association, fusion, promotion after K observations over T seconds, false-positive
// rejection (one-frame blobs, label confusions), what counts as in view, and the observed
// fraction behind the fully-observed rule.
#include <gtest/gtest.h>

#include "semantics_test_util.hpp"
#include "semx/semantics/pipeline.hpp"
#include "semx/semantics/tracker.hpp"
#include "semx/simulator/sensor_noise.hpp"

using namespace semx::semantics;
using namespace semx::semantics::test;

namespace {

constexpr int64_t kFrameUs = 33333;

// A detection whose points cover the surface of an axis-aligned box (4 cm grid).
Detection3D box_detection(SemanticClass cls, const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  Detection3D d;
  d.cls = cls;
  const Eigen::Vector3d lo = centre - size / 2, hi = centre + size / 2;
  for (double x = lo.x(); x <= hi.x() + 1e-9; x += 0.04) {
    for (double y = lo.y(); y <= hi.y() + 1e-9; y += 0.04) {
      for (double z = lo.z(); z <= hi.z() + 1e-9; z += 0.04) {
        const bool surface = x - lo.x() < 0.04 || hi.x() - x < 0.04 || y - lo.y() < 0.04 ||
                             hi.y() - y < 0.04 || z - lo.z() < 0.04 || hi.z() - z < 0.04;
        if (surface) d.points.emplace_back(x, y, z);
      }
    }
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : d.points) {
    d.box.extend(p.cast<double>());
    sum += p.cast<double>();
  }
  d.centroid = sum / static_cast<double>(d.points.size());
  return d;
}

// A frame whose camera looks along world -x from the origin: nothing at x > 0 is in view.
Frame looking_away(int64_t utime) {
  Frame f = blank_frame(640, 480, utime);
  f.pose.linear() =
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix() * semx::runtime::optical_in_body();
  return f;
}

const Track* track_of(const ObjectTracker& t, SemanticClass c) {
  for (const auto& tr : t.tracks()) {
    if (tr.cls == c) return &tr;
  }
  return nullptr;
}

}  // namespace

TEST(Association, SameClassWithinTheGateJoinsItsTrack) {
  ObjectTracker tracker{SemanticsConfig{}};
  const Eigen::Vector3d a(2, 0, 0.45), b(3, 0, 0.45), size(0.45, 0.45, 0.9);
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d jitter(0.01 * (k % 3), -0.01 * (k % 2), 0);
    tracker.update(looking_away(k * kFrameUs), {box_detection(SemanticClass::kChair, a + jitter, size),
                                                box_detection(SemanticClass::kChair, b - jitter, size)});
  }
  ASSERT_EQ(tracker.tracks().size(), 2u);
  for (const auto& t : tracker.tracks()) {
    EXPECT_EQ(t.observations, 10);
    const bool near_a = (t.centroid() - a).norm() < 0.05, near_b = (t.centroid() - b).norm() < 0.05;
    EXPECT_TRUE(near_a || near_b) << t.centroid().transpose();
  }
  EXPECT_NE(tracker.tracks()[0].id, tracker.tracks()[1].id);
}

TEST(Association, OtherClassesAndFarDetectionsStartNewTracks) {
  ObjectTracker tracker{SemanticsConfig{}};
  const Eigen::Vector3d size(0.45, 0.45, 0.9);
  tracker.update(looking_away(0), {box_detection(SemanticClass::kChair, {2, 0, 0.45}, size)});
  // Same place, other class: never the chair's track.
  tracker.update(looking_away(kFrameUs), {box_detection(SemanticClass::kTable, {2, 0, 0.45}, size)});
  // Same class beyond the gate (a gap of 0.35 m > 0.25 m).
  tracker.update(looking_away(2 * kFrameUs), {box_detection(SemanticClass::kChair, {2.8, 0, 0.45}, size)});
  EXPECT_EQ(tracker.tracks().size(), 3u);
  // Within the gate (a gap of 0.15 m): joins.
  tracker.update(looking_away(3 * kFrameUs), {box_detection(SemanticClass::kChair, {1.4, 0, 0.45}, size)});
  EXPECT_EQ(tracker.tracks().size(), 3u);
}

TEST(Association, OneDetectionPerTrackPerFrame) {
  ObjectTracker tracker{SemanticsConfig{}};
  const Eigen::Vector3d size(0.45, 0.45, 0.9);
  tracker.update(looking_away(0), {box_detection(SemanticClass::kChair, {2, 0, 0.45}, size)});
  // Two detections within the gate of the one track: the nearer joins, the other starts a track.
  tracker.update(looking_away(kFrameUs), {box_detection(SemanticClass::kChair, {2.5, 0, 0.45}, size),
                                          box_detection(SemanticClass::kChair, {2.0, 0, 0.45}, size)});
  ASSERT_EQ(tracker.tracks().size(), 2u);
  EXPECT_EQ(tracker.tracks()[0].observations, 2);
  EXPECT_NEAR(tracker.tracks()[0].centroid().x(), 2.0, 0.05);
  EXPECT_EQ(tracker.tracks()[1].observations, 1);
}

TEST(Association, OverlappingTracksOfOneClassMerge) {
  ObjectTracker tracker{SemanticsConfig{}};
  // Two halves of a sofa seen as separate detections in one frame, then the whole sofa.
  tracker.update(looking_away(0), {box_detection(SemanticClass::kSofa, {2, -0.5, 0.4}, {0.9, 1.0, 0.8}),
                                   box_detection(SemanticClass::kSofa, {2, 0.5, 0.4}, {0.9, 1.0, 0.8})});
  ASSERT_EQ(tracker.tracks().size(), 2u);
  const auto whole = box_detection(SemanticClass::kSofa, {2, 0, 0.4}, {0.9, 2.0, 0.8});
  tracker.update(looking_away(kFrameUs), {whole});
  // The whole sofa joined one half; surface seen in one frame only does not shape a box yet.
  EXPECT_EQ(tracker.tracks().size(), 2u);
  tracker.update(looking_away(2 * kFrameUs), {whole});
  // Now its box covers the other half, which merged into it.
  ASSERT_EQ(tracker.tracks().size(), 1u);
  EXPECT_NEAR(tracker.tracks()[0].extent().y(), 2.0, 0.1);
  EXPECT_EQ(tracker.tracks()[0].observations, 4);
}

TEST(Promotion, NeedsKObservationsOverTSeconds) {
  SemanticsConfig c;
  ObjectTracker tracker(c);
  const auto det = box_detection(SemanticClass::kChair, {2, 0, 0.45}, {0.45, 0.45, 0.9});
  int64_t t = 0;
  int frames = 0;
  while (!track_of(tracker, SemanticClass::kChair) || !track_of(tracker, SemanticClass::kChair)->region) {
    tracker.update(looking_away(t), {det});
    ++frames;
    t += kFrameUs;
    ASSERT_LT(frames, 100);
  }
  // 30 Hz: K = 5 frames come after 0.13 s; T = 0.5 s needs 16 periods (15 are 0.49999 s).
  EXPECT_EQ(frames, 17);
  const Track* tr = track_of(tracker, SemanticClass::kChair);
  EXPECT_GE(tr->observation_span_utime, 500000);

  // Many observations in a short time are not enough either.
  ObjectTracker fast(c);
  for (int k = 0; k < 50; ++k) fast.update(looking_away(k * 1000), {det});
  EXPECT_FALSE(fast.tracks()[0].region);
}

TEST(FalsePositives, AOneFrameBlobNeverBecomesARegion) {
  Scene scene(room({Solid::box(SemanticClass::kChair, {4.0, 2.5, 0.45}, {0.45, 0.45, 0.9})}));
  SemanticsConfig c;
  SemanticPipeline sem(c);
  const Eigen::Vector3d eye(1.5, 2.5, 1.4);
  for (int k = 0; k < 150; ++k) {
    Frame f = scene.render(eye, 0.1 * std::sin(k * 0.05), k * kFrameUs, k);
    if (k == 10) {
      // A "tv" disc painted on the far wall for one frame.
      for (int v = 100; v < 160; ++v) {
        for (int u = 400; u < 460; ++u) {
          f.class_label[static_cast<std::size_t>(v) * 640 + u] = static_cast<uint16_t>(SemanticClass::kTv);
          f.instance_label[static_cast<std::size_t>(v) * 640 + u] = 65000;
        }
      }
    }
    sem.process(f);
    if (k == 11) {
      EXPECT_NE(track_of(sem.tracker(), SemanticClass::kTv), nullptr);  // it was tracked
    }
  }
  const auto regions = sem.regions();
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].cls, SemanticClass::kChair);
  EXPECT_LT((regions[0].centroid - Eigen::Vector3d(4.0, 2.5, 0.45)).norm(), 0.15);
  EXPECT_EQ(track_of(sem.tracker(), SemanticClass::kTv), nullptr);  // missed while in view: deleted
}

TEST(FalsePositives, HeavyDetectionNoiseLeavesOnlyTheRealObjects) {
  Scene scene(room({Solid::box(SemanticClass::kCabinet, {4.5, 1.5, 0.45}, {0.5, 1.0, 0.9}),
                    Solid::cylinder(SemanticClass::kPlant, {4.2, 3.5, 0.6}, 0.25, 1.2)}));
  semx::simulator::DetectionNoiseConfig noise;
  noise.enabled = true;
  noise.miss_probability = 0.2;
  noise.confusion_probability = 0.2;  // 4x the simulator's default
  noise.spurious_rate = 3.0;          // 15x
  SemanticPipeline sem{SemanticsConfig{}};
  const Eigen::Vector3d eye(1.0, 2.5, 1.4);
  for (int k = 0; k < 240; ++k) {  // 8 s panning slowly across the room
    auto raw = scene.render_raw(eye, 0.35 * std::sin(k * 0.03), k * kFrameUs, k);
    semx::simulator::apply_detection_noise(raw, noise, 77 + static_cast<uint64_t>(k));
    sem.process(to_frame(raw));
  }
  const auto regions = sem.regions();
  ASSERT_EQ(regions.size(), 2u);
  for (const auto& r : regions) {
    if (r.cls == SemanticClass::kCabinet) {
      EXPECT_LT((r.centroid - Eigen::Vector3d(4.5, 1.5, 0.45)).norm(), 0.15);
    } else {
      EXPECT_EQ(r.cls, SemanticClass::kPlant);
      EXPECT_LT((r.centroid - Eigen::Vector3d(4.2, 3.5, 0.6)).norm(), 0.2);
    }
  }
}

TEST(InView, VisibleUnoccludedAndBigEnough) {
  Scene scene(room({Solid::box(SemanticClass::kChair, {4.0, 2.5, 0.45}, {0.45, 0.45, 0.9}),
                    Solid::box(SemanticClass::kShelf, {2.5, 1.0, 1.0}, {0.3, 1.2, 2.0})}));
  SemanticPipeline sem{SemanticsConfig{}};
  const Eigen::Vector3d eye(1.0, 2.5, 1.4);
  for (int k = 0; k < 20; ++k) sem.process(scene.render(eye, 0.0, k * kFrameUs, k));
  const Track* chair = track_of(sem.tracker(), SemanticClass::kChair);
  ASSERT_NE(chair, nullptr);
  const ObjectTracker& t = sem.tracker();
  EXPECT_TRUE(t.in_view(*chair, scene.render(eye, 0.0)));
  EXPECT_FALSE(t.in_view(*chair, scene.render(eye, M_PI)));                   // looking away
  EXPECT_FALSE(t.in_view(*chair, scene.render({3.0, 2.5, 1.4}, -M_PI / 2)));  // beside the image
  const Eigen::Vector3d hidden(2.0, 0.5, 1.4);
  EXPECT_FALSE(
      t.in_view(*chair, scene.render(hidden, look_at(hidden, {4.0, 2.5, 0.45}))));  // behind the shelf
  EXPECT_TRUE(t.in_view(*chair, scene.render({5.5, 2.5, 1.4}, M_PI)));              // from the other side
}

TEST(ObservedFraction, GrowsAsTheCameraCirclesAndTheRegionGoesInactive) {
  const Eigen::Vector3d centre(3.0, 2.5, 0.4);
  Scene scene(room({Solid::box(SemanticClass::kTable, centre, {0.8, 0.8, 0.8})}));
  SemanticPipeline sem{SemanticsConfig{}};
  int64_t k = 0;
  auto watch = [&](const Eigen::Vector3d& eye, int frames) {
    for (int i = 0; i < frames; ++i, ++k)
      sem.process(scene.render(eye, look_at(eye, centre), k * kFrameUs, k));
  };
  watch({1.2, 2.5, 1.4}, 30);  // one side only
  auto regions = sem.regions();
  ASSERT_EQ(regions.size(), 1u);
  const double one_side = regions[0].observed_fraction;
  EXPECT_GT(one_side, 0.2);
  EXPECT_LT(one_side, 0.8);
  EXPECT_TRUE(regions[0].active);
  // Around it: the fraction grows, and once it passes 0.8 the region stops rewarding.
  for (int a = 1; a < 8; ++a) {
    const double ang = M_PI + a * M_PI / 4;
    watch(centre + Eigen::Vector3d(1.8 * std::cos(ang), 1.8 * std::sin(ang), 1.0), 10);
  }
  regions = sem.regions();
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_GT(regions[0].observed_fraction, one_side);
  EXPECT_GE(regions[0].observed_fraction, SemanticsConfig{}.tracking.fully_observed_fraction);
  EXPECT_FALSE(regions[0].active);
  EXPECT_DOUBLE_EQ(reward(regions[0], centre), 0.0);
}

TEST(ObservedFraction, AnObjectAgainstAWallCanBeFullyObservedWithoutItsBack) {
  // A shelf against the wall y = 5: its back face can never be seen, and never counts.
  const Eigen::Vector3d centre(3.0, 4.8, 0.9);
  Scene scene(room({Solid::box(SemanticClass::kShelf, centre, {1.2, 0.4, 1.8})}));
  SemanticPipeline sem{SemanticsConfig{}};
  int64_t k = 0;
  auto watch = [&](const Eigen::Vector3d& eye, int frames) {
    for (int i = 0; i < frames; ++i, ++k)
      sem.process(scene.render(eye, look_at(eye, centre), k * kFrameUs, k));
  };
  watch({3.0, 2.5, 1.4}, 20);
  ASSERT_EQ(sem.regions().size(), 1u);
  EXPECT_TRUE(sem.regions()[0].active);
  watch({1.2, 3.6, 1.4}, 20);
  watch({4.8, 3.6, 1.4}, 20);
  watch({1.0, 4.6, 1.4}, 20);
  watch({5.0, 4.6, 1.4}, 20);
  const auto regions = sem.regions();
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_FALSE(regions[0].active) << "observed fraction " << regions[0].observed_fraction;
}
