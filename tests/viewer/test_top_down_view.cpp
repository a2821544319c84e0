// TopDownView on its pixels: a hand-made map, roadmap, region, path, trail and pose land where
// and in the colours they should; hostile input (NaN, far, too many) is dropped or capped and
// never breaks a frame; the frame schedule follows message time.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "semx/viewer/top_down_view.hpp"

namespace semx::viewer {
namespace {

using evaluator::Image;
using evaluator::Rgb;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const Eigen::Vector4d kIdentity(1, 0, 0, 0);

bool near(Rgb a, Rgb b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol;
}

// True when some pixel within `r` of (x, y) is within `tol` of `c`.
bool near_pixel(const Image& img, Eigen::Vector2i p, Rgb c, int tol, int r = 1) {
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int x = p.x() + dx, y = p.y() + dy;
      if (x >= 0 && y >= 0 && x < img.width && y < img.height && near(img.at(x, y), c, tol)) return true;
    }
  }
  return false;
}

// A 6 x 4 m area at 0.1 m: free everywhere in the band at y < 2 m, an occupied column at
// (4.55, 3.55), unknown elsewhere.
map::StateGrid hand_map() {
  map::StateGrid g(0.1);
  for (int x = 0; x < 60; ++x) {
    for (int y = 0; y < 20; ++y) g.set_state({x, y, 10}, map::VoxelState::kFree);
  }
  g.set_state({45, 35, 10}, map::VoxelState::kFree);
  g.set_state({45, 35, 11}, map::VoxelState::kOccupied);
  g.set_state({45, 35, 40}, map::VoxelState::kOccupied);  // above the band: not drawn
  return g;
}

TopDownViewOptions fixed_options() {
  TopDownViewOptions o;
  o.area = std::make_pair(Eigen::Vector2d(0, 0), Eigen::Vector2d(6, 4));
  o.scale_px_per_m = 50;  // 5 px per voxel
  return o;
}

Roadmap three_nodes() {
  Roadmap r;
  r.iteration = 7;
  RoadmapNode a, b, c;
  a.id = 10, a.position = {1, 0.5, 1}, a.score = 0;
  b.id = 11, b.position = {3, 0.5, 1}, b.score = 10;
  c.id = 12, c.position = {5, 0.5, 1}, c.score = 5;
  r.nodes = {a, b, c};
  r.edges = {{10, 11}, {11, 12}};
  return r;
}

TEST(TopDownView, DrawsEachLayerInItsColourAtItsPlace) {
  const map::StateGrid grid = hand_map();
  TopDownView view(fixed_options());
  view.set_time(12500000);
  // Trail west to east along y = 3.5, then the vehicle stops at (2, 3) facing +x.
  for (int i = 0; i <= 10; ++i) view.add_pose(i * 100000, {0.5 + 0.1 * i, 3.5, 1}, kIdentity);
  ASSERT_TRUE(view.add_pose(2000000, {2, 3, 1}, kIdentity));
  ASSERT_TRUE(view.set_roadmap(three_nodes()));
  Region chair;
  chair.class_id = 5;
  chair.label = "chair";
  chair.centroid = {4, 2.7, 0.5};
  chair.radius = 0.6;
  chair.weight = 0.8;
  ASSERT_TRUE(view.set_regions({chair}));
  ASSERT_TRUE(view.set_path({{1, 1.5, 1}, {5, 1.5, 1}}));
  view.set_planner({"semantic-dep", 2, "", 7});

  const evaluator::MapPicture pic = view.picture(&grid);
  EXPECT_EQ(pic.pixels_per_column(), 5);
  const Image img = pic.render();
  const evaluator::MapPictureOptions defaults;
  auto px = [&](double x, double y) { return pic.pixel({x, y}); };
  auto at = [&](double x, double y) {
    const Eigen::Vector2i p = px(x, y);
    return img.at(p.x(), p.y());
  };

  // Columns: free below y = 2 m (away from the overlays), occupied at (4.55, 3.55), unknown else.
  EXPECT_EQ(at(0.25, 1.05), defaults.free);
  EXPECT_EQ(at(4.55, 3.55), defaults.occupied);
  EXPECT_EQ(at(5.5, 3.8), defaults.unknown);
  // Nodes: lowest, highest and middle score.
  EXPECT_EQ(at(1, 0.5), TopDownView::score_color(0));
  EXPECT_EQ(at(3, 0.5), TopDownView::score_color(1));
  EXPECT_EQ(at(5, 0.5), TopDownView::score_color(0.5));
  EXPECT_NE(TopDownView::score_color(0), TopDownView::score_color(1));
  // Edges between them, coloured by the mean of their ends.
  EXPECT_TRUE(near_pixel(img, px(2, 0.5), TopDownView::edge_color(0.5), 12));
  EXPECT_TRUE(near_pixel(img, px(4, 0.5), TopDownView::edge_color(0.75), 12));
  // The path.
  EXPECT_TRUE(near_pixel(img, px(3, 1.5), TopDownViewOptions{}.path, 10));
  // The region: a translucent disc over unknown space, its ring at the radius.
  const Rgb rc = TopDownView::region_color(5);
  const Rgb blend{static_cast<uint8_t>(std::lround(0.25 * rc.r + 0.75 * defaults.unknown.r)),
                  static_cast<uint8_t>(std::lround(0.25 * rc.g + 0.75 * defaults.unknown.g)),
                  static_cast<uint8_t>(std::lround(0.25 * rc.b + 0.75 * defaults.unknown.b))};
  EXPECT_TRUE(near(at(4, 2.5), blend, 3)) << int(at(4, 2.5).r) << "," << int(at(4, 2.5).g);
  EXPECT_TRUE(near_pixel(img, px(4, 2.7 - 0.6), rc, 10));
  // The trail, the vehicle and its heading arrow (east of it).
  EXPECT_TRUE(near_pixel(img, px(1.0, 3.5), TopDownViewOptions{}.trail, 10));
  EXPECT_EQ(at(2, 3), TopDownViewOptions{}.vehicle);
  EXPECT_TRUE(near_pixel(img, px(2.45, 3), TopDownViewOptions{}.vehicle, 10));
  EXPECT_FALSE(near_pixel(img, px(1.55, 3), TopDownViewOptions{}.vehicle, 10));

  const std::string h = view.header(&grid);
  EXPECT_NE(h.find("t 12.5 s"), std::string::npos) << h;
  EXPECT_NE(h.find("known 1.2 m3"), std::string::npos) << h;  // 1203 voxels of 1 dm3
  EXPECT_NE(h.find("semantic-dep EXECUTING #7"), std::string::npos) << h;
}

TEST(TopDownView, DrawsTheControllersTrajectoryAlongItsCurve) {
  // Collinear, evenly spaced control points: a cubic B-spline on the line, from the average
  // (q0 + 4 q1 + q2) / 6 of the first three to that of the last three.
  TrajectoryCurve line;
  line.knot_interval = 0.25;
  for (int i = 0; i < 8; ++i) line.control_points.emplace_back(0.5 + 0.5 * i, 2.5, 1.0);
  const std::vector<Eigen::Vector3d> pts = sample_curve(line, 0.05);
  ASSERT_EQ(pts.size(), 5u * 5 + 1);
  EXPECT_NEAR(pts.front().x(), 1.0, 1e-12);
  EXPECT_NEAR(pts.back().x(), 3.5, 1e-12);
  for (size_t i = 1; i < pts.size(); ++i) {
    EXPECT_NEAR(pts[i].y(), 2.5, 1e-12);
    EXPECT_NEAR(pts[i].x() - pts[i - 1].x(), 0.1, 1e-9) << "uniform speed on a uniform line";
  }
  line.control_points.resize(3);
  EXPECT_TRUE(sample_curve(line).empty()) << "too few control points for a cubic";

  const map::StateGrid grid = hand_map();
  TopDownView view(fixed_options());
  TrajectoryCurve c;
  c.knot_interval = 0.25;
  for (int i = 0; i < 8; ++i) c.control_points.emplace_back(0.5 + 0.5 * i, 2.5, 1.0);
  ASSERT_TRUE(view.set_trajectory(c));
  evaluator::MapPicture pic = view.picture(&grid);
  Image img = pic.render();
  EXPECT_TRUE(near_pixel(img, pic.pixel({2.5, 2.5}), TopDownViewOptions{}.trajectory, 10));
  // The fallback in its own colour; NaN control points are dropped, not drawn.
  c.optimized = false;
  c.control_points.insert(c.control_points.begin() + 2, Eigen::Vector3d(kNaN, 0, 0));
  ASSERT_TRUE(view.set_trajectory(c));
  EXPECT_EQ(view.trajectory().size(), pts.size());
  pic = view.picture(&grid);
  img = pic.render();
  EXPECT_TRUE(near_pixel(img, pic.pixel({2.5, 2.5}), TopDownViewOptions{}.fallback_trajectory, 10));
  EXPECT_FALSE(near_pixel(img, pic.pixel({2.5, 2.5}), TopDownViewOptions{}.trajectory, 10));
  // A knot interval off the wire that is no time: its control polygon.
  c.knot_interval = kNaN;
  ASSERT_TRUE(view.set_trajectory(c));
  EXPECT_EQ(view.trajectory().size(), 8u);
  view.clear_run();
  EXPECT_TRUE(view.trajectory().empty());
}

TEST(TopDownView, NodesAreColouredByTheRankOfTheirScore) {
  TopDownView view;
  Roadmap r;
  for (const double s : {1.0, 1000.0, 2.0, 2.0, kNaN}) {
    RoadmapNode n;
    n.id = static_cast<int64_t>(r.nodes.size());
    n.score = s;
    r.nodes.push_back(n);
  }
  ASSERT_TRUE(view.set_roadmap(r));
  const std::vector<double> t = view.normalized_scores();
  ASSERT_EQ(t.size(), 5u);
  EXPECT_DOUBLE_EQ(t[0], 0);
  EXPECT_DOUBLE_EQ(t[1], 1);
  EXPECT_DOUBLE_EQ(t[2], 0.5);  // a tie shares the mean rank: (1 + 2) / 2 of 3
  EXPECT_DOUBLE_EQ(t[3], 0.5);
  EXPECT_TRUE(std::isnan(t[4]));
  EXPECT_EQ(TopDownView::score_color(t[4]), (Rgb{150, 150, 150}));
}

TEST(TopDownView, FacesWhereTheQuaternionSays) {
  TopDownView view(fixed_options());
  // 90 degrees about z: facing +y.
  const double s = std::sqrt(0.5);
  ASSERT_TRUE(view.add_pose(0, {3, 1, 1}, {s, 0, 0, s}));
  EXPECT_NEAR(view.yaw(), M_PI / 2, 1e-9);
  const evaluator::MapPicture pic = view.picture(nullptr);
  const Image img = pic.render();
  EXPECT_TRUE(near_pixel(img, pic.pixel({3, 1.45}), TopDownViewOptions{}.vehicle, 10));
  // A quaternion that is not one keeps the last heading.
  ASSERT_TRUE(view.add_pose(1, {3, 1, 1}, {kNaN, 0, 0, 0}));
  EXPECT_NEAR(view.yaw(), M_PI / 2, 1e-9);
}

TEST(TopDownView, DropsNaNFarAndTooManyInputs) {
  TopDownView view;
  EXPECT_FALSE(view.add_pose(0, {kNaN, 0, 0}, kIdentity));
  EXPECT_FALSE(view.add_pose(0, {1e30, 0, 0}, kIdentity));
  EXPECT_FALSE(view.add_pose(0, {0, -std::numeric_limits<double>::infinity(), 0}, kIdentity));
  EXPECT_TRUE(view.trail().empty());
  EXPECT_FALSE(view.position());

  Roadmap r;
  for (int i = 0; i < 12000; ++i) {
    RoadmapNode n;
    n.id = i;
    n.position = {0.01 * (i % 100), 0.01 * (i / 100), 1};
    n.score = i % 3 == 0 ? kNaN : i;
    r.nodes.push_back(n);
    r.edges.emplace_back(i, i + 1);
  }
  r.nodes[3].position.x() = kNaN;
  r.nodes[5].position.y() = 1e12;
  r.nodes.push_back(r.nodes[0]);  // a duplicate id
  r.edges.emplace_back(-99, 0);   // to a node that does not exist
  ASSERT_TRUE(view.set_roadmap(r));
  const ViewLimits lim;
  EXPECT_EQ(view.roadmap().nodes.size(), lim.max_nodes);
  for (const auto& n : view.roadmap().nodes) EXPECT_TRUE(n.position.allFinite());
  EXPECT_LE(view.roadmap().edges.size(), lim.max_nodes);
  for (const auto& [a, b] : view.roadmap().edges) {
    EXPECT_NE(a, 3);
    EXPECT_NE(b, 3);
    EXPECT_GE(a, 0);
  }
  // Non-finite scores are drawn grey, the others normalised.
  const auto t = view.normalized_scores();
  EXPECT_TRUE(std::isnan(t[0]));
  for (const double x : t) EXPECT_TRUE(std::isnan(x) || (x >= 0 && x <= 1));

  std::vector<Region> regions(400);
  for (size_t i = 0; i < regions.size(); ++i) {
    regions[i].centroid = {1, 1, 1};
    regions[i].radius = 0.5;
    regions[i].label = std::string("tv\n\x01\xff") + std::string(100, 'x');
  }
  regions[0].radius = kNaN;
  regions[1].radius = -1;
  regions[2].radius = 1e9;
  regions[3].centroid.z() = kNaN;
  regions[4].weight = kNaN;
  ASSERT_TRUE(view.set_regions(regions));
  EXPECT_EQ(view.regions().size(), lim.max_regions);
  EXPECT_DOUBLE_EQ(view.regions()[0].radius, lim.max_radius_m);  // the 1e9 one, clamped
  EXPECT_EQ(view.regions()[1].weight, 0);
  for (const auto& g : view.regions()) {
    EXPECT_LE(g.label.size(), lim.max_label_chars);
    for (const char c : g.label) EXPECT_TRUE(c >= 32 && c < 127);
  }

  EXPECT_FALSE(view.set_path({{kNaN, 0, 0}, {0, 1e300, 0}}));
  EXPECT_TRUE(view.path().empty());
  EXPECT_TRUE(view.set_path({{0, 0, 1}, {kNaN, 1, 1}, {1, 1, 1}}));
  EXPECT_EQ(view.path().size(), 2u);

  view.set_planner({"p\x07lanner", 99, std::string(500, 'r'), -3});
  EXPECT_NE(view.header(nullptr).find("p?lanner state 99"), std::string::npos);
  EXPECT_GT(view.skipped(), 7000);

  // It all still draws, within the size limits.
  const Image img = view.render(nullptr);
  EXPECT_GT(img.width, 100);
  EXPECT_LE(img.width, lim.max_side_px + 400);
  EXPECT_LE(img.height, lim.max_side_px + 100);
}

TEST(TopDownView, FarItemsCannotBlowUpThePicture) {
  TopDownView view;
  map::StateGrid grid(0.1);
  grid.set_state({0, 0, 10}, map::VoxelState::kFree);
  grid.set_state({90000, -90000, 10}, map::VoxelState::kOccupied);  // 9 km away
  ASSERT_TRUE(view.add_pose(0, {1, 1, 1}, kIdentity));
  RoadmapNode far;
  far.position = {9999, -9999, 1};
  ASSERT_TRUE(view.set_roadmap({0, 0, {far}, {}}));
  const evaluator::MapView v = view.update_view(&grid);
  const ViewLimits lim;
  EXPECT_LE(v.hi.x() - v.lo.x(), lim.max_side_px * 0.1 + 1e-9);
  EXPECT_LE(v.hi.y() - v.lo.y(), lim.max_side_px * 0.1 + 1e-9);
  // The window keeps the vehicle in view.
  EXPECT_TRUE(v.lo.x() <= 1 && 1 <= v.hi.x() && v.lo.y() <= 1 && 1 <= v.hi.y());
  const Image img = view.render(&grid);
  EXPECT_LE(img.width, lim.max_side_px + 400);
}

TEST(TopDownView, TheAreaGrowsWithWhatIsSeenAndNeverShrinks) {
  TopDownViewOptions o;
  o.margin_m = 1;
  o.snap_m = 2;
  TopDownView view(o);
  evaluator::MapView v = view.update_view(nullptr);
  EXPECT_EQ(v.lo, Eigen::Vector2d(-5, -5));  // nothing seen yet
  view.clear_run();
  TopDownView fresh(o);
  fresh.add_pose(0, {0.3, 0.3, 1}, kIdentity);
  v = fresh.update_view(nullptr);
  EXPECT_EQ(v.lo, Eigen::Vector2d(-2, -2));
  EXPECT_EQ(v.hi, Eigen::Vector2d(2, 2));
  fresh.add_pose(1, {5, 0.3, 1}, kIdentity);
  v = fresh.update_view(nullptr);
  EXPECT_EQ(v.hi, Eigen::Vector2d(6, 2));
  fresh.clear_run();
  EXPECT_TRUE(fresh.trail().empty());
  v = fresh.update_view(nullptr);
  EXPECT_EQ(v.lo, Eigen::Vector2d(-2, -2));
  EXPECT_EQ(v.hi, Eigen::Vector2d(6, 2));
}

TEST(TopDownView, AWorldGivesTheAreaAndFaintWalls) {
  const simulator::World world = simulator::parse_world(R"(name: box
bounds: {min: [-0.2, -0.2, -0.1], max: [3.2, 2.7, 1.7]}
start: {position: [1.0, 1.2, 0.8], yaw_deg: 0}
solids:
  - {type: box, class: floor, center: [1.5, 1.25, -0.05], size: [3.4, 2.9, 0.1]}
  - {type: box, class: wall, center: [-0.1, 1.25, 0.8], size: [0.2, 2.5, 1.6]}
)",
                                                        "box.yaml");
  TopDownView view;
  view.set_world(world);
  map::StateGrid grid(0.1);
  const evaluator::MapPicture pic = view.picture(&grid);
  EXPECT_GT(pic.count(evaluator::MapPicture::Column::kUnmappedWall), 20);
  const Image img = pic.render();
  EXPECT_EQ(img.at(pic.pixel({-0.15, 1.25}).x(), pic.pixel({-0.15, 1.25}).y()), TopDownViewOptions{}.walls);
  const evaluator::MapView v = view.update_view(&grid);
  EXPECT_EQ(v.lo, Eigen::Vector2d(-0.2, -0.2));
  EXPECT_EQ(v.hi, Eigen::Vector2d(3.2, 2.7));
}

TEST(TopDownView, ALongTrailIsThinnedNotCut) {
  TopDownViewOptions o;
  o.limits.max_trail_points = 100;
  o.trail_step_m = 0.05;
  TopDownView view(o);
  for (int i = 0; i < 1000; ++i) view.add_pose(i, {0.1 * i, 0, 1}, kIdentity);
  EXPECT_LE(view.trail().size(), 100u);
  EXPECT_GE(view.trail().size(), 50u);
  EXPECT_DOUBLE_EQ(view.trail().front().x(), 0);
  EXPECT_NEAR(view.trail().back().x(), 99.9, 1e-9);
  // Standing still adds nothing.
  const size_t n = view.trail().size();
  for (int i = 0; i < 50; ++i) view.add_pose(2000 + i, {99.9, 0.01, 1}, kIdentity);
  EXPECT_EQ(view.trail().size(), n);
}

TEST(FrameSchedule, OneFramePerPeriodOfMessageTime) {
  FrameSchedule s(0.5);
  EXPECT_EQ(s.period_us(), 500000);
  EXPECT_EQ(s.due(0), 0);
  EXPECT_EQ(s.due(100000), -1);
  EXPECT_EQ(s.due(499999), -1);
  EXPECT_EQ(s.due(500000), 1);
  EXPECT_EQ(s.due(2300000), 4);   // a jump: one frame, the latest
  EXPECT_EQ(s.due(1000000), -1);  // time going back
  EXPECT_EQ(s.due(-5), -1);
  EXPECT_EQ(s.due(2600000), 5);
  s.reset();
  EXPECT_EQ(s.due(0), 0);
  EXPECT_EQ(FrameSchedule(kNaN).period_us(), 1000000);
  EXPECT_EQ(FrameSchedule(-1).period_us(), 1);
  EXPECT_EQ(frame_file_name(123), "frame_000123.png");
  EXPECT_EQ(frame_file_name(1234567), "frame_1234567.png");
}

TEST(PlannerStateName, NamesAndOthers) {
  EXPECT_EQ(planner_state_name(0), "INIT");
  EXPECT_EQ(planner_state_name(4), "DONE");
  EXPECT_EQ(planner_state_name(-7), "state -7");
}

}  // namespace
}  // namespace semx::viewer
