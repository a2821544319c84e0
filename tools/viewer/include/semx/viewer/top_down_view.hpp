// The live viewer's picture (docs/viewer.md): the latest map, the flown trail, the planner's
// roadmap, the semantic regions, the current path and the vehicle's pose, drawn top-down with
// evaluator::MapPicture. No LCM here: the node converts messages into the plain values below.
//
//   TopDownView view;                      // or TopDownView(options) with a world / an area
//   view.add_pose(utime, position, q);     // ODOMETRY
//   view.set_roadmap(roadmap);             // ROADMAP, SEMANTIC_REGIONS, PLAN_PATH, ...
//   view.render(&mirror.grid()).rgb;       // or write_png(&grid, "frame_000012.png")
//
// Every setter sanitises what it is given, because it comes off the wire: non-finite or absurdly
// far positions are skipped, counts are capped (ViewLimits), labels are trimmed to printable
// ASCII. What was dropped is counted (skipped()), never fatal.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "semx/core/roadmap_values.hpp"
#include "semx/evaluator/map_picture.hpp"
#include "semx/evaluator/rgb.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"

namespace semx::viewer {

// ROADMAP and SEMANTIC_REGIONS: the values the ROS bridge forwards too.
using core::Region;
using core::Roadmap;
using core::RoadmapNode;

// The controller's trajectory (TRAJECTORY): a uniform B-spline of position control points.
struct TrajectoryCurve {
  int degree = 3;
  double knot_interval = 0.25;  // s
  std::vector<Eigen::Vector3d> control_points;
  bool optimized = true;  // false: the fallback, on the planner's path at lower speed
};
// Points of the curve every `step_s` of its time (degree 3; any other degree: its control
// polygon). Empty when there are fewer control points than degree + 1.
std::vector<Eigen::Vector3d> sample_curve(const TrajectoryCurve& c, double step_s = 0.05);

struct PlannerInfo {
  std::string planner;
  int state = -1;  // planner_status_t's INIT..FAILED; -1: nothing heard
  std::string reason;
  int64_t iteration = 0;
};
// "INIT", ..., "FAILED"; "state N" for anything else.
std::string planner_state_name(int state);

// What one message may put on the picture; beyond it the rest is dropped (and counted).
struct ViewLimits {
  size_t max_nodes = 5000;
  size_t max_edges = 20000;
  size_t max_regions = 256;
  size_t max_path_points = 5000;
  size_t max_trail_points = 20000;  // beyond it the trail is thinned (every other point)
  size_t max_label_chars = 32;
  double max_coord_m = 1e4;   // |x|, |y|, |z| beyond this is not a position
  double max_radius_m = 50;   // larger region radii are clamped
  double max_extent_m = 400;  // the area shown never grows beyond this side
  int max_side_px = 2000;     // nor the picture beyond this many pixels a side (map part)
};

struct TopDownViewOptions {
  // Pixels per metre; rounded to whole pixels per voxel (at least 1). 0: fit `fit_side_px`.
  double scale_px_per_m = 0;
  int fit_side_px = 900;
  // The area shown. Unset: the world's bounds when a world is given, else everything seen so
  // far (map, trail, roadmap, path, regions) plus `margin_m`, snapped outward to `snap_m` and
  // never shrinking, so consecutive frames line up.
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> area;
  double margin_m = 1.0;
  double snap_m = 2.0;
  // Heights projected into the columns; unset: the world's (MapView::of_world), else 0.15..2.2.
  std::optional<std::pair<double, double>> z_band;
  double trail_step_m = 0.05;  // a new trail point when the vehicle moved this far
  double arrow_length_m = 0.6;
  ViewLimits limits;
  bool legend = true;

  evaluator::Rgb trail{30, 90, 220};
  evaluator::Rgb path{200, 30, 200};
  evaluator::Rgb trajectory{240, 140, 0};           // optimised
  evaluator::Rgb fallback_trajectory{150, 90, 40};  // the fallback
  evaluator::Rgb vehicle{0, 150, 160};
  evaluator::Rgb goal{0, 150, 60};
  evaluator::Rgb walls{176, 176, 192};  // ground-truth walls the map does not know (faint)
  evaluator::Rgb no_score{150, 150, 150};
};

class TopDownView {
 public:
  explicit TopDownView(TopDownViewOptions options = {});

  // Draws the world's walls faintly where the map knows nothing; its bounds become the area and
  // its heights the band unless the options set them. The ground truth is built at the map's
  // resolution when the first frame with a map is drawn.
  void set_world(simulator::World world);

  // ---- state (each returns false when the input was unusable as a whole) ----
  bool add_pose(int64_t utime, const Eigen::Vector3d& position, const Eigen::Vector4d& q_wxyz);
  bool set_roadmap(Roadmap roadmap);
  bool set_regions(std::vector<Region> regions);
  bool set_path(std::vector<Eigen::Vector3d> waypoints);
  bool set_trajectory(const TrajectoryCurve& curve);
  void set_planner(PlannerInfo info);
  // The simulation time the header shows (the node's message time).
  void set_time(int64_t utime) { utime_ = utime; }
  // A new episode: the trail and the planner's outputs go, the map and the area stay.
  void clear_run();

  // ---- what is held (after sanitising) ----
  const std::vector<Eigen::Vector3d>& trail() const { return trail_; }
  const Roadmap& roadmap() const { return roadmap_; }
  const std::vector<Region>& regions() const { return regions_; }
  const std::vector<Eigen::Vector3d>& path() const { return path_; }
  const std::vector<Eigen::Vector3d>& trajectory() const { return trajectory_; }
  const PlannerInfo& planner() const { return planner_; }
  std::optional<Eigen::Vector3d> position() const { return pose_position_; }
  double yaw() const { return yaw_; }
  int64_t time_utime() const { return utime_; }
  // Items dropped so far: non-finite or far positions, entries beyond the limits.
  int64_t skipped() const { return skipped_; }

  // ---- drawing ----
  // The header line: sim time, known volume of `grid`, planner and its state.
  std::string header(const map::StateGrid* grid) const;
  // The area and heights the next frame shows (grows the remembered area; see options).
  evaluator::MapView update_view(const map::StateGrid* grid);
  // The picture of the current state over `grid` (nullptr: no map yet), with every overlay.
  evaluator::MapPicture picture(const map::StateGrid* grid);
  evaluator::Image render(const map::StateGrid* grid) { return picture(grid).render(); }
  void write_png(const map::StateGrid* grid, const std::string& path) { picture(grid).write_png(path); }

  // Colours: score_color(t) for a node whose score ranks at the fraction t in [0, 1] of the
  // roadmap's finite scores (0 the lowest, 1 the highest; purple, orange, red); edges take the
  // mean of their ends, lightened.
  static evaluator::Rgb score_color(double t);
  static evaluator::Rgb edge_color(double t);
  // A region's colour: by class, from the evaluator's palette.
  static evaluator::Rgb region_color(int class_id);
  // The rank fraction of each held node's score (NaN for a non-finite score), as drawn.
  std::vector<double> normalized_scores() const;

 private:
  bool plausible(const Eigen::Vector3d& p) const;
  std::string clean_label(const std::string& s) const;
  void include(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);

  TopDownViewOptions options_;
  std::optional<simulator::World> world_;
  std::optional<simulator::GroundTruth> gt_;
  map::StateGrid empty_grid_{0.1};

  std::vector<Eigen::Vector3d> trail_;
  std::optional<Eigen::Vector3d> pose_position_;
  double yaw_ = 0;
  int64_t last_pose_utime_ = -1;
  Roadmap roadmap_;
  std::vector<Region> regions_;
  std::vector<Eigen::Vector3d> path_;
  std::vector<Eigen::Vector3d> trajectory_;
  bool trajectory_optimized_ = true;
  PlannerInfo planner_;
  int64_t utime_ = 0;
  int64_t skipped_ = 0;

  // The remembered area (grows only), when neither options nor a world fix it.
  bool have_area_ = false;
  Eigen::Vector2d area_lo_{0, 0}, area_hi_{0, 0};
};

// When a frame is due on message time: one per `period_s`, frame k covering [k·p, (k+1)·p).
// The first message time at or after k·p makes frame k due (rendered before that message is
// applied, so frame k shows everything stamped before k·p). Time that jumps several periods ahead
// gives one frame, the latest; time that goes back is ignored until reset() (a new episode).
class FrameSchedule {
 public:
  explicit FrameSchedule(double period_s);
  // The index of the frame due at `utime`, or -1.
  int64_t due(int64_t utime);
  void reset() { last_ = -1; }
  int64_t last_index() const { return last_; }
  int64_t period_us() const { return period_us_; }

 private:
  int64_t period_us_;
  int64_t last_ = -1;
};

// "frame_000123.png"
std::string frame_file_name(int64_t index);

}  // namespace semx::viewer
