// A top-down picture of the map (map.png): every column of voxels inside a height range is
// drawn occupied (any occupied voxel), else free (any free voxel), else unknown; optionally the
// ground truth's walls where the map knows nothing; then overlays in world coordinates:
// polylines (the flown trajectory, a path, roadmap edges), circles with labels (semantic
// regions, roadmap nodes), markers, arrows (a heading) and text. A scale bar, a legend and a
// title frame it.
//
//   MapPicture pic(mirror.grid(), MapView::of_world(world));
//   pic.underlay_ground_truth(gt);
//   pic.add_polyline(xy_points, {30, 90, 220}, 2);
//   pic.add_circle({3.3, 4.7}, 1.5, {230, 120, 0}, "tv 0.8");
//   pic.write_png("run/map.png");
//
// Nothing of OpenCV shows here: the columns are classified when the picture is made, overlays
// are kept as values and drawn by render(). Overlays are clipped to the map's frame (the title,
// scale bar and legend around it stay clear), and their labels are placed last, on top, by a
// LabelPlacer (label_placer.hpp): none overlaps another or a labelled marker, a crowded one
// moves out with a leader line or is left out.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "semx/evaluator/rgb.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"

namespace semx::evaluator {

// The area shown (x, y, metres) and the heights whose voxels are projected.
struct MapView {
  Eigen::Vector2d lo{0, 0};
  Eigen::Vector2d hi{10, 10};
  double z_lo = 0.1;
  double z_hi = 2.5;

  // The world's bounds; heights from 0.3 m above the bounds' floor to 0.4 m below their top,
  // which leaves out the floor and ceiling slabs of the shipped worlds and their surface voxels.
  static MapView of_world(const simulator::World& world);
};

struct MapPictureOptions {
  int max_side_px = 1000;  // pixels per voxel chosen so the longer side is at most this (>= 1 px)
  // > 0: exactly this many pixels per voxel column, whatever max_side_px says (a fixed scale,
  // e.g. the viewer's --scale, so frames of one run line up).
  int pixels_per_column = 0;
  int margin_px = 36;  // room for the title, scale bar and legend
  std::string title;
  bool legend = true;
  Rgb free{245, 245, 240};
  Rgb occupied{40, 40, 48};
  Rgb unknown{204, 204, 204};
  Rgb unmapped_wall{140, 140, 165};  // ground truth occupied, map unknown
  Rgb background{255, 255, 255};
};

class MapPicture {
 public:
  enum class Column : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2, kUnmappedWall = 3 };

  MapPicture(const map::StateGrid& grid, const MapView& view, MapPictureOptions options = {});

  // Columns the map does not know but the ground truth holds occupied voxels in (same height
  // range) are drawn as unmapped walls.
  void underlay_ground_truth(const simulator::GroundTruth& gt);

  // ---- overlays (world metres; drawn in the order added) ----
  void add_polyline(const std::vector<Eigen::Vector2d>& points, Rgb color, int thickness_px = 2);
  void add_polyline(const std::vector<Eigen::Vector3d>& points, Rgb color, int thickness_px = 2);
  void add_segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb color, int thickness_px = 1);
  // Many segments blended over what lies beneath at `alpha` (0..1) as one layer, so that
  // thousands of roadmap edges fade into the map instead of burying it.
  void add_segments(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& segments, Rgb color,
                    int thickness_px = 1, double alpha = 1.0);
  // Many small dots without outline or label (roadmap nodes), blended at `alpha`.
  void add_dots(const std::vector<Eigen::Vector2d>& points, Rgb color, int radius_px = 1, double alpha = 1.0);
  // A circle of radius_m (filled or outlined, its outline blended at `alpha`) with an optional
  // label at its centre.
  void add_circle(const Eigen::Vector2d& center, double radius_m, Rgb color, const std::string& label = "",
                  bool filled = false, int thickness_px = 2, double alpha = 1.0);
  // A dot of fixed pixel size (start, end, nodes), with an optional label.
  void add_marker(const Eigen::Vector2d& p, Rgb color, const std::string& label = "", int radius_px = 5);
  void add_text(const Eigen::Vector2d& p, const std::string& text, Rgb color);
  // An arrow from `from` to `to` (a heading: the vehicle's pose in the viewer).
  void add_arrow(const Eigen::Vector2d& from, const Eigen::Vector2d& to, Rgb color, int thickness_px = 2);
  // An extra legend entry (colour swatch and text).
  void add_legend(const std::string& text, Rgb color);

  // ---- geometry ----
  int columns_x() const { return nx_; }
  int columns_y() const { return ny_; }
  int pixels_per_column() const { return ppc_; }
  Column column(int ix, int iy) const { return cells_[static_cast<size_t>(iy) * nx_ + ix]; }
  // Pixel of a world point in the rendered image (y up in the world is up in the picture).
  // Points far outside the view (or not finite) map to a far-away pixel, never to an overflow.
  Eigen::Vector2i pixel(const Eigen::Vector2d& p) const;
  int64_t count(Column c) const;

  Image render() const;
  void write_png(const std::string& path) const;

 private:
  struct Overlay {
    enum Kind { kPolyline, kCircle, kMarker, kText, kArrow, kSegments, kDots } kind;
    std::vector<Eigen::Vector2d> points;  // kSegments: pairs
    double radius = 0;
    Rgb color;
    std::string text;
    bool filled = false;
    int thickness = 1;
    double alpha = 1.0;
  };

  MapView view_;
  MapPictureOptions options_;
  double res_;
  int32_t kx0_, ky0_, kz0_, kz1_;  // key ranges
  int nx_, ny_, ppc_;
  std::vector<Column> cells_;
  std::vector<Overlay> overlays_;
  std::vector<std::pair<std::string, Rgb>> legend_;
};

// The trajectory's colour in map.png: a saturated blue no other overlay uses, drawn last on a
// white halo so the flight stands out of the roadmap and the regions.
inline constexpr Rgb kTrajectoryColour{0, 70, 255};

// The evaluator's map.png: the map over the world's area (MapView::of_world), the ground truth's
// walls the map does not know (when `gt` is given), and the flown trajectory with its start and
// end. `beneath` adds overlays under the trajectory (the roadmap, the regions); overlays added
// to the result draw on top.
MapPicture run_map_picture(const map::StateGrid& grid, const simulator::World& world,
                           const simulator::GroundTruth* gt, const std::vector<Eigen::Vector3d>& trajectory,
                           const std::string& title,
                           const std::function<void(MapPicture&)>& beneath = nullptr);

}  // namespace semx::evaluator
