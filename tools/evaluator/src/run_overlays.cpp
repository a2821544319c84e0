#include "semx/evaluator/run_overlays.hpp"

#include <octomap/OcTree.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "semx/map/voxel_key.hpp"

namespace semx::evaluator {

namespace {
// Grey roadmap, faded under everything; orange informative nodes with an outline; magenta
// regions; none of them the trajectory's blue (kTrajectoryColour).
constexpr Rgb kEdge{95, 105, 125};
constexpr double kEdgeAlpha = 0.22;
constexpr Rgb kNode{110, 118, 130};
constexpr Rgb kInformativeNode{255, 150, 0};
constexpr double kInformativeShare = 0.25;  // of the roadmap's highest gain
constexpr Rgb kActiveRegion{200, 0, 160};
constexpr double kRegionAlpha = 0.6;
constexpr Rgb kDoneRegion{90, 90, 90};
constexpr int32_t kOctoOffset = 32768;  // OctoMap's key of coordinate 0 at depth 16

// The colour `c` blended at `alpha` over the map's free colour: the legend's swatch of a
// faded overlay looks like the overlay.
Rgb faded(Rgb c, double alpha) {
  const Rgb bg = MapPictureOptions{}.free;
  auto mix = [&](uint8_t a, uint8_t b) {
    return static_cast<uint8_t>(std::lround(alpha * a + (1 - alpha) * b));
  };
  return {mix(c.r, bg.r), mix(c.g, bg.g), mix(c.b, bg.b)};
}
}  // namespace

std::vector<size_t> informative_nodes(const RoadmapOverlay& roadmap) {
  const size_t n = roadmap.nodes.size();
  const bool gains = roadmap.gain.size() == n;
  double best = 0;
  for (size_t i = 0; gains && i < n; ++i)
    if (std::isfinite(roadmap.gain[i])) best = std::max(best, roadmap.gain[i]);
  std::vector<size_t> out;
  for (size_t i = 0; i < n; ++i) {
    if (!(i < roadmap.frontier.size() && roadmap.frontier[i])) continue;
    if (gains && !(best > 0 && roadmap.gain[i] >= kInformativeShare * best)) continue;
    out.push_back(i);
  }
  return out;
}

void add_roadmap(MapPicture& picture, const RoadmapOverlay& roadmap) {
  picture.add_segments(roadmap.edges, kEdge, 1, kEdgeAlpha);
  std::vector<bool> marked(roadmap.nodes.size(), false);
  std::vector<Eigen::Vector2d> plain, informative;
  for (const size_t i : informative_nodes(roadmap)) marked[i] = true;
  for (size_t i = 0; i < roadmap.nodes.size(); ++i)
    (marked[i] ? informative : plain).push_back(roadmap.nodes[i]);
  picture.add_dots(plain, kNode, 1, 0.8);
  picture.add_dots(informative, kInformativeNode, 2);
  if (!roadmap.edges.empty()) picture.add_legend("roadmap edges", faded(kEdge, 0.5));
  if (!roadmap.nodes.empty())
    picture.add_legend("roadmap nodes (" + std::to_string(roadmap.nodes.size()) + ")", kNode);
  if (!informative.empty()) {
    picture.add_legend("informative nodes (gain >= max/4: " + std::to_string(informative.size()) + ")",
                       kInformativeNode);
  }
}

void add_regions(MapPicture& picture, const std::vector<RegionOverlay>& regions) {
  // A region still attracting the planner shows its reward radius (faded: regions overlap); an
  // observed one only where it is, so a finished run is not a tangle of circles.
  for (const auto& r : regions) {
    if (r.active) {
      picture.add_circle(r.centre, r.radius, kActiveRegion, r.label, false, 1, kRegionAlpha);
    } else {
      picture.add_marker(r.centre, kDoneRegion, r.label, 3);
    }
  }
  if (!regions.empty()) {
    picture.add_legend("semantic regions, active", kActiveRegion);
    picture.add_legend("semantic regions, observed (" + std::to_string(regions.size()) + " in all)",
                       kDoneRegion);
  }
}

int64_t write_octomap_bt(const map::StateGrid& grid, const std::string& path) {
  octomap::OcTree tree(grid.resolution());
  const float occupied = static_cast<float>(tree.getClampingThresMaxLog());
  const float free = static_cast<float>(tree.getClampingThresMinLog());
  int64_t written = 0;
  for (const map::VoxelKey& bk : grid.sorted_block_keys()) {
    const map::VoxelBlock* b = grid.find_block(bk);
    if (!b) continue;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      const map::VoxelState s = b->state[i];
      if (s == map::VoxelState::kUnknown) continue;
      const map::VoxelKey k = map::voxel_of(bk, i);
      if (k.x < -kOctoOffset || k.x >= kOctoOffset || k.y < -kOctoOffset || k.y >= kOctoOffset ||
          k.z < -kOctoOffset || k.z >= kOctoOffset)
        continue;
      const octomap::OcTreeKey ok(static_cast<uint16_t>(k.x + kOctoOffset),
                                  static_cast<uint16_t>(k.y + kOctoOffset),
                                  static_cast<uint16_t>(k.z + kOctoOffset));
      tree.setNodeValue(ok, s == map::VoxelState::kOccupied ? occupied : free, /*lazy_eval=*/true);
      ++written;
    }
  }
  tree.updateInnerOccupancy();
  // Debian's liboctomap reports " done." with fprintf(stderr) on every write, which would land
  // in the middle of the evaluator's final table: stderr goes to /dev/null for the call.
  std::fflush(stderr);
  const int saved = dup(STDERR_FILENO);
  const int null_fd = open("/dev/null", O_WRONLY);
  if (saved >= 0 && null_fd >= 0) dup2(null_fd, STDERR_FILENO);
  const bool ok = tree.writeBinary(path);
  std::fflush(stderr);
  if (saved >= 0) {
    dup2(saved, STDERR_FILENO);
    close(saved);
  }
  if (null_fd >= 0) close(null_fd);
  if (!ok) throw std::runtime_error("octomap file '" + path + "': cannot write");
  return written;
}

}  // namespace semx::evaluator
