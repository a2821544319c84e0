#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "semx/core/random.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "semx/simulator/ray_caster.hpp"
#include "semx/simulator/sensor_noise.hpp"
#include "test_util.hpp"

namespace semx::simulator {
namespace {

using runtime::kDepthInvalid;
using runtime::kDepthNoReturn;
using runtime::PinholeCamera;

// Optical frame at `p` for a body with yaw, then pitch (nose down positive) and roll.
Eigen::Isometry3d camera_pose(const Eigen::Vector3d& p, double yaw, double pitch = 0, double roll = 0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix() *
      runtime::optical_in_body();
  T.translation() = p;
  return T;
}

// A wall whose face is the plane n·p = d (n horizontal at angle phi), far larger than the view.
World wall_world(double d, double phi) {
  World w;
  w.bounds = {{-50, -50, -50}, {50, 50, 50}};
  const Eigen::Vector3d n(std::cos(phi), std::sin(phi), 0);
  Solid s = Solid::box(SemanticClass::kWall, (d + 0.5) * n, {1.0, 60.0, 60.0}, phi);
  s.instance = 42;
  w.solids.push_back(s);
  return w;
}

TEST(Render, DepthMatchesAnalyticWallDistanceEveryPixel) {
  struct Case {
    double d, phi, yaw, pitch, roll;
  };
  const Case cases[] = {{2.0, 0, 0, 0, 0},
                        {2.5, 20 * M_PI / 180, -15 * M_PI / 180, 0, 0},
                        {1.5, -35 * M_PI / 180, 10 * M_PI / 180, 12 * M_PI / 180, 5 * M_PI / 180},
                        {3.7, 100 * M_PI / 180, 80 * M_PI / 180, -8 * M_PI / 180, 0}};
  const PinholeCamera cam;
  for (const auto& c : cases) {
    SCOPED_TRACE(::testing::Message() << "d=" << c.d << " phi=" << c.phi << " yaw=" << c.yaw);
    const World w = wall_world(c.d, c.phi);
    Rasterizer r(w);
    CameraFrame f;
    const Eigen::Isometry3d pose = camera_pose(Eigen::Vector3d::Zero(), c.yaw, c.pitch, c.roll);
    r.render(cam, pose, kRenderDepth | kRenderLabels, f);
    const Eigen::Vector3d n(std::cos(c.phi), std::sin(c.phi), 0);
    int checked = 0, valid = 0;
    double worst = 0;
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const double nd = n.dot(pose.linear() * cam.ray(u, v));
        const double t = nd > 0 ? c.d / nd : 1e9;  // z-depth: the optical ray has z = 1
        const uint16_t got = f.depth.at(u, v);
        if (std::abs(t - cam.max_range) < 1e-3 || std::abs(t - cam.min_range) < 1e-3) continue;
        ++checked;
        if (t > cam.max_range) {
          ASSERT_EQ(got, kDepthNoReturn) << u << "," << v;
          ASSERT_EQ(f.class_label.at(u, v), 0);
        } else {
          ASSERT_EQ(f.class_label.at(u, v), static_cast<uint16_t>(SemanticClass::kWall)) << u << "," << v;
          ASSERT_EQ(f.instance_label.at(u, v), 42);
          if (t < cam.min_range) {
            ASSERT_EQ(got, kDepthInvalid);
          } else {
            ++valid;
            worst = std::max(worst, std::abs(got - 1000.0 * t));
          }
        }
      }
    }
    EXPECT_LE(worst, 0.51);  // mm rounding only
    EXPECT_GT(valid, cam.width * cam.height / 4);
    EXPECT_GT(checked, cam.width * cam.height * 99 / 100);
  }
}

TEST(Render, RangeLimitsGiveReservedValues) {
  const PinholeCamera cam;
  CameraFrame f;
  {
    Rasterizer r(wall_world(0.3, 0));  // closer than min_range: seen, not measured
    r.render(cam, camera_pose({0, 0, 0}, 0), kRenderAll, f);
    EXPECT_EQ(f.depth.at(320, 240), kDepthInvalid);
    EXPECT_EQ(f.class_label.at(320, 240), static_cast<uint16_t>(SemanticClass::kWall));
  }
  {
    RasterizerOptions o;
    o.rgb_far = 20;
    Rasterizer r(wall_world(6.0, 0), o);  // beyond max_range: no return, no label, still in RGB
    r.render(cam, camera_pose({0, 0, 0}, 0), kRenderAll, f);
    EXPECT_EQ(f.depth.at(320, 240), kDepthNoReturn);
    EXPECT_EQ(f.class_label.at(320, 240), 0);
    EXPECT_EQ(f.instance_label.at(320, 240), 0);
    EXPECT_NE(f.rgb.at(320, 240), kBackgroundRgb);
  }
}

// Fraction of pixels on which two frames agree: depth within tol_mm (reserved values equal) and
// identical class and instance labels.
struct Agreement {
  double depth = 0, labels = 0;
};
Agreement compare(const CameraFrame& a, const CameraFrame& b, int tol_mm) {
  size_t d_ok = 0, l_ok = 0;
  const size_t n = a.depth.data.size();
  for (size_t i = 0; i < n; ++i) {
    const int da = a.depth.data[i], db = b.depth.data[i];
    const bool ra = da == kDepthInvalid || da == kDepthNoReturn,
               rb = db == kDepthInvalid || db == kDepthNoReturn;
    d_ok += (ra || rb) ? da == db : std::abs(da - db) <= tol_mm;
    l_ok += a.class_label.data[i] == b.class_label.data[i] &&
            a.instance_label.data[i] == b.instance_label.data[i];
  }
  return {static_cast<double>(d_ok) / n, static_cast<double>(l_ok) / n};
}

TEST(Render, NearPlaneClipsTrianglesThatCrossIt) {
  // In the middle of a 10 m room the floor's and ceiling's triangles reach behind the camera;
  // dropping them would leave the bottom and top of the image empty.
  const World w = test::box_room(10, 10, 3);
  const PinholeCamera cam;
  Rasterizer r(w);
  CameraFrame f;
  const Eigen::Isometry3d pose = camera_pose({5, 5, 1.0}, 0.3);
  r.render(cam, pose, kRenderDepth | kRenderLabels, f);
  int floor_px = 0;
  for (int v = 300; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d dir = pose.linear() * cam.ray(u, v);
      const double t = 1.0 / -dir.z();  // floor plane z = 0, camera at z = 1
      if (t > 3.0) continue;            // nearer than any wall from the middle of the room
      ASSERT_EQ(f.class_label.at(u, v), static_cast<uint16_t>(SemanticClass::kFloor)) << u << "," << v;
      ASSERT_NEAR(f.depth.at(u, v), 1000.0 * t, 0.51) << u << "," << v;
      ++floor_px;
    }
  }
  EXPECT_GT(floor_px, 40000);
  // Right against a wall, looking along it: the wall's triangles cross the near plane.
  const Eigen::Isometry3d grazing = camera_pose({5, 0.3, 1.2}, -0.2, 0.1);
  r.render(cam, grazing, kRenderDepth | kRenderLabels, f);
  CameraFrame ref;
  RayCaster(w).render(cam, grazing, kRenderDepth | kRenderLabels, ref);
  const Agreement a = compare(f, ref, 1);
  EXPECT_GE(a.depth, 0.999);
  EXPECT_GE(a.labels, 0.999);
}

TEST(Render, LabelsAreTheSolidHit) {
  World w = test::box_room(6, 6, 3);
  Solid chair = Solid::box(SemanticClass::kChair, {3, 1.5, 0.45}, {0.45, 0.45, 0.9}, 0.3);
  chair.instance = 11;
  Solid plant = Solid::cylinder(SemanticClass::kPlant, {3, 3.2, 0.6}, 0.25, 1.2);
  plant.instance = 12;
  w.solids.push_back(chair);
  w.solids.push_back(plant);
  const PinholeCamera cam;
  Rasterizer r(w);
  RayCaster rc(w);
  CameraFrame f;
  // Looking at each object's centre from 2 m: the centre pixel must carry its labels.
  for (const Solid& s : {chair, plant}) {
    const Eigen::Vector3d eye = s.center - Eigen::Vector3d(2.0, 0, 0);
    r.render(cam, camera_pose(eye, 0), kRenderDepth | kRenderLabels, f);
    EXPECT_EQ(f.class_label.at(320, 240), static_cast<uint16_t>(s.cls));
    EXPECT_EQ(f.instance_label.at(320, 240), s.instance);
  }
  // Everywhere: the labels are those of the solid the reference ray hits.
  const Eigen::Isometry3d pose = camera_pose({0.8, 2.3, 1.0}, 0.1, 0.25);
  r.render(cam, pose, kRenderDepth | kRenderLabels, f);
  int mismatches = 0, objects = 0;
  for (int v = 0; v < cam.height; v += 2) {
    for (int u = 0; u < cam.width; u += 2) {
      const auto hit = rc.cast(pose.translation(), pose.linear() * cam.ray(u, v), 1e-9, cam.max_range);
      const uint16_t cls = hit ? static_cast<uint16_t>(w.solids[hit->solid].cls) : 0;
      const uint16_t inst = hit ? w.solids[hit->solid].instance : 0;
      mismatches += f.class_label.at(u, v) != cls || f.instance_label.at(u, v) != inst;
      objects += inst == 11 || inst == 12;
    }
  }
  EXPECT_GT(objects, 1000);
  EXPECT_LE(mismatches, 80 * 60 / 100);  // silhouette pixels only (< 0.1 %)
}

TEST(Render, RgbIsLambertShadedClassColour) {
  const World w = test::box_room(6, 6, 3);
  const PinholeCamera cam;
  RasterizerOptions o;
  o.rgb_far = 20;  // RGB sees past the depth range
  Rasterizer r(w, o);
  RayCaster rc(w);
  CameraFrame f;
  const Eigen::Isometry3d pose = camera_pose({1, 1, 1.5}, 0.6, 0.2);
  r.render(cam, pose, kRenderAll, f);
  int same = 0, total = 0;
  std::set<std::tuple<int, int, int>> distinct;
  for (int v = 0; v < cam.height; v += 4) {
    for (int u = 0; u < cam.width; u += 4) {
      const auto hit = rc.cast(pose.translation(), pose.linear() * cam.ray(u, v), 1e-9, 100);
      ASSERT_TRUE(hit);
      const Rgb want = WorldMesh::shade(w.solids[hit->solid].color, hit->normal);
      same += f.rgb.at(u, v) == want;
      ++total;
      distinct.insert({f.rgb.at(u, v).r, f.rgb.at(u, v).g, f.rgb.at(u, v).b});
    }
  }
  EXPECT_GE(same, total * 99 / 100);
  EXPECT_GE(distinct.size(), 4u);  // floor, ceiling and two walls shade differently
}

// The rasteriser draws and resolves in bands of rows and merges runs of pixels: every subset of
// channels, every image size (bands and SIMD blocks that do not divide it) and the RGB runs must
// give the same pixels as the full render.
TEST(Render, ChannelsAndImageSizesGiveTheSamePixels) {
  const World w = test::shipped("env2");
  const GroundTruth gt(w, 0.1);
  const VehicleReachability reach(gt, w.start.position);
  for (double rgb_far : {0.0, 20.0}) {
    RasterizerOptions o;
    o.rgb_far = rgb_far;
    Rasterizer r(w, o);
    RayCaster rc(w);
    core::XoshiroRng rng(11);
    for (const auto& [width, height] : {std::pair{640, 480}, {333, 77}, {7, 5}}) {
      PinholeCamera cam;
      cam.width = width;
      cam.height = height;
      cam.fx = cam.fy = width / 2.0;
      cam.cx = width / 2.0;
      cam.cy = height / 2.0;
      for (int frames = 0; frames < 3;) {
        const Eigen::Vector3d p(rng.uniform(w.bounds.min.x(), w.bounds.max.x()),
                                rng.uniform(w.bounds.min.y(), w.bounds.max.y()), rng.uniform(0.5, 2.2));
        if (!reach.reachable(p)) continue;
        ++frames;
        const Eigen::Isometry3d pose = camera_pose(p, rng.uniform(-M_PI, M_PI), rng.uniform(-0.3, 0.3));
        CameraFrame all, part;
        r.render(cam, pose, kRenderAll | kRenderRgbRuns, all);
        EXPECT_EQ(all.rgb_runs, rgb_runs(all.rgb));
        r.render(cam, pose, kRenderDepth | kRenderLabels, part);
        EXPECT_EQ(part.depth, all.depth);
        EXPECT_EQ(part.class_label, all.class_label);
        EXPECT_EQ(part.instance_label, all.instance_label);
        r.render(cam, pose, kRenderRgbRuns, part);
        EXPECT_EQ(part.rgb_runs, all.rgb_runs);
        r.render(cam, pose, kRenderRgb, part);
        EXPECT_EQ(part.rgb, all.rgb);
        if (width < 100) {
          rc.render(cam, pose, kRenderRgbRuns, part, rgb_far);
          EXPECT_EQ(part.rgb_runs, rgb_runs(part.rgb)) << "the reference renders runs too";
        }
      }
    }
  }
}

// Issue 3's acceptance: the fast renderer against the reference on the shipped worlds.
TEST(Render, RasterizerAgreesWithRayCasterOnShippedWorlds) {
  PinholeCamera cam;  // 90 deg FOV at quarter resolution keeps the reference affordable
  cam.width = 320;
  cam.height = 240;
  cam.fx = cam.fy = 160;
  cam.cx = 160;
  cam.cy = 120;
  for (const char* name : {"env1", "env2", "env3"}) {
    SCOPED_TRACE(name);
    const World w = test::shipped(name);
    const GroundTruth gt(w, 0.1);
    const VehicleReachability reach(gt, w.start.position);
    Rasterizer r(w);
    RayCaster rc(w);
    core::XoshiroRng rng(5);
    int frames = 0;
    CameraFrame a, b;
    while (frames < 4) {
      const Eigen::Vector3d p(rng.uniform(w.bounds.min.x(), w.bounds.max.x()),
                              rng.uniform(w.bounds.min.y(), w.bounds.max.y()), rng.uniform(0.5, 2.2));
      if (!reach.reachable(p)) continue;
      const Eigen::Isometry3d pose = camera_pose(p, rng.uniform(-M_PI, M_PI), rng.uniform(-0.2, 0.2));
      r.render(cam, pose, kRenderDepth | kRenderLabels, a);
      rc.render(cam, pose, kRenderDepth | kRenderLabels, b);
      const Agreement ag = compare(a, b, 10);
      EXPECT_GE(ag.depth, 0.995) << "pose " << p.transpose();
      EXPECT_GE(ag.labels, 0.995) << "pose " << p.transpose();
      ++frames;
    }
  }
}

TEST(DepthNoise, StatisticsFollowTheModelAndSeed) {
  DepthNoiseConfig c;
  c.enabled = true;
  Image<uint16_t> img(200, 200, 3000);
  img.at(0, 0) = kDepthInvalid;
  img.at(1, 0) = kDepthNoReturn;
  Image<uint16_t> a = img, b = img, other = img;
  apply_depth_noise(a, c, 9);
  apply_depth_noise(b, c, 9);
  apply_depth_noise(other, c, 10);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, other);
  EXPECT_EQ(a.at(0, 0), kDepthInvalid);
  EXPECT_EQ(a.at(1, 0), kDepthNoReturn);
  double sum = 0, sq = 0;
  const size_t n = a.data.size() - 2;
  for (size_t i = 2; i < a.data.size(); ++i) {
    sum += a.data[i] - 3000.0;
    sq += (a.data[i] - 3000.0) * (a.data[i] - 3000.0);
  }
  const double sigma_mm = 1000 * (c.sigma_0 + c.sigma_2 * 9.0);  // 18.3 mm at 3 m
  EXPECT_NEAR(sum / n, 0.0, 0.5);
  EXPECT_NEAR(std::sqrt(sq / n), sigma_mm, 0.05 * sigma_mm);
  c.enabled = false;
  Image<uint16_t> untouched = img;
  apply_depth_noise(untouched, c, 9);
  EXPECT_EQ(untouched, img);
}

TEST(DetectionNoise, MissesConfusesAndInventsObjects) {
  World w = test::box_room(6, 6, 3);
  for (int k = 0; k < 4; ++k) {
    Solid s = Solid::box(SemanticClass::kChair, {3.5, 1.5 + 0.9 * k, 0.45}, {0.45, 0.45, 0.9});
    s.instance = static_cast<uint16_t>(20 + k);
    w.solids.push_back(s);
  }
  Rasterizer r(w);
  CameraFrame clean;
  r.render(PinholeCamera{}, camera_pose({1.0, 3.0, 0.8}, 0, 0.2), kRenderDepth | kRenderLabels, clean);
  auto count = [](const CameraFrame& f, uint16_t cls) {
    return std::count(f.class_label.data.begin(), f.class_label.data.end(), cls);
  };
  const uint16_t chair = static_cast<uint16_t>(SemanticClass::kChair);
  ASSERT_GT(count(clean, chair), 1000);

  DetectionNoiseConfig c;
  c.enabled = true;
  c.spurious_rate = 0;
  c.miss_probability = 1;
  CameraFrame f = clean;
  apply_detection_noise(f, c, 1);
  EXPECT_EQ(count(f, chair), 0);
  EXPECT_EQ(count(f, static_cast<uint16_t>(SemanticClass::kWall)),
            count(clean, static_cast<uint16_t>(SemanticClass::kWall)));

  c.miss_probability = 0;
  c.confusion_probability = 1;
  f = clean;
  apply_detection_noise(f, c, 1);
  EXPECT_EQ(count(f, chair), 0);
  EXPECT_EQ(f.instance_label, clean.instance_label);  // relabelled, not removed

  c.confusion_probability = 0;
  c.spurious_rate = 5;
  f = clean;
  apply_detection_noise(f, c, 3);
  CameraFrame g = clean;
  apply_detection_noise(g, c, 3);
  EXPECT_EQ(f.class_label, g.class_label);
  EXPECT_GT(std::count_if(f.instance_label.data.begin(), f.instance_label.data.end(),
                          [](uint16_t i) { return i >= kSpuriousInstanceBase; }),
            100);
}

}  // namespace
}  // namespace semx::simulator
