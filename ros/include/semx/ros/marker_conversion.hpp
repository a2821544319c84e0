// The planner's roadmap and semantics' regions as visualization_msgs/MarkerArray, for rviz.
//
// Roadmap (namespaces "roadmap/nodes", "roadmap/edges", "roadmap/path"): nodes as one
// SPHERE_LIST coloured by score (dark blue lowest, yellow highest of the cycle; roadmap.hpp's
// G + R_sem over T_path), edges as one faded LINE_LIST (they would bury the map at full
// strength), the nodes on the path to the goal larger and orange. Regions: one translucent
// SPHERE of radius r per region in its class's colour (fainter once fully observed, when it
// rewards nothing) and a TEXT_VIEW_FACING label "class #id" above it; marker id = region id.
// Every array starts with DELETEALL, so markers of nodes and regions that are gone disappear.
//
// The read-back functions recover what the markers carry (positions, edges, flags on the path,
// region ids, centres, radii, classes); colours are drawn from scores and are not read back.
#pragma once

#include <string>
#include <vector>

#include "semx/ros/bridge_values.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

msg::MarkerArray roadmap_markers(const Roadmap& r, const std::string& frame, int64_t stamp_ns);
msg::MarkerArray region_markers(const std::vector<Region>& regions, const std::string& frame, int64_t stamp_ns);

// Colour of a score in [lo, hi] on a blue-green-yellow ramp (viridis-like).
msg::Color score_color(double score, double lo, double hi);

// Node positions (in the order sent), edges as index pairs into them, and the ON_PATH flags.
// False when the array is not a roadmap_markers() array.
bool roadmap_from_markers(const msg::MarkerArray& a, Roadmap& out);
// Regions with id, class (from the label's name), label, centroid, radius and active.
bool regions_from_markers(const msg::MarkerArray& a, std::vector<Region>& out);

}  // namespace semx::rosbridge
