#include "semx/evaluator/run_overlays.hpp"

#include <octomap/OcTree.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>

#include "semx/map/voxel_key.hpp"

namespace semx::evaluator {

namespace {
constexpr Rgb kEdge{170, 190, 220};
constexpr Rgb kNode{60, 90, 200};
constexpr Rgb kFrontierNode{240, 150, 0};
constexpr Rgb kActiveRegion{200, 0, 160};
constexpr Rgb kDoneRegion{120, 120, 120};
constexpr int32_t kOctoOffset = 32768;  // OctoMap's key of coordinate 0 at depth 16
}  // namespace

void add_roadmap(MapPicture& picture, const RoadmapOverlay& roadmap) {
  for (const auto& [a, b] : roadmap.edges) picture.add_segment(a, b, kEdge, 1);
  for (size_t i = 0; i < roadmap.nodes.size(); ++i) {
    const bool frontier = i < roadmap.frontier.size() && roadmap.frontier[i];
    picture.add_marker(roadmap.nodes[i], frontier ? kFrontierNode : kNode, "", 2);
  }
  if (!roadmap.nodes.empty()) {
    picture.add_legend("roadmap (" + std::to_string(roadmap.nodes.size()) + " nodes)", kNode);
  }
}

void add_regions(MapPicture& picture, const std::vector<RegionOverlay>& regions) {
  // A region still attracting the planner shows its reward radius; an observed one only where
  // it is, so a finished run is not a tangle of circles.
  for (const auto& r : regions) {
    if (r.active) {
      picture.add_circle(r.centre, r.radius, kActiveRegion, r.label, false, 1);
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
