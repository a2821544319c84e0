// Ray-casting integration of a depth frame into an OccupancyMap.
//
// Per frame, every voxel gets at most one observation, and "hit" wins over "miss" (OctoMap's
// insertPointCloud semantics): the voxel containing a valid return is a hit; voxels the ray
// crosses between the camera and the return are misses. Returns of 0xFFFF (nothing within range)
// and returns beyond max_range clear free space up to max_range along the ray, excluding the
// voxel containing the max-range point (as OctoMap's maxrange does); invalid (0) and too-near
// returns are ignored. All of it is counted in the IntegrationReport.
//
// Speed: rays are walked on a dense scratch grid over the view frustum (a byte per voxel, so a
// voxel seen by many rays is updated once, from its marks, in a second pass; Fast-Planner's
// per-frame stamps), from their end point back to the camera. The mode (IntegrationParams)
// decides which rays are walked: every one (exact), or one per end voxel and quadrant of it
// across the ray (bundled: the other rays ending there take nearly the same way back), or
// Fast-Planner's scheme. docs/mapper.md gives the measured speed and agreement with OctoMap.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "semx/map/map_delta.hpp"
#include "semx/mapper/depth_frame.hpp"
#include "semx/mapper/mapper_config.hpp"
#include "semx/mapper/occupancy_map.hpp"

namespace semx::mapper {

struct IntegrationReport {
  bool accepted = false;
  std::string error;  // why a frame was rejected (pose not finite, size mismatch, ...)

  // Pixels considered (after pixel_step), by outcome.
  int64_t pixels = 0;
  int64_t hits = 0;          // valid returns: free ray + occupied end voxel
  int64_t no_return = 0;     // 0xFFFF: free ray up to max range
  int64_t beyond_range = 0;  // deeper than max range: free ray up to max range
  int64_t too_near = 0;      // shallower than min range: ignored
  int64_t invalid = 0;       // 0: ignored

  int64_t rays_walked = 0;     // rays whose end voxel was new this frame
  int64_t voxels_updated = 0;  // voxels that received an observation
  int64_t voxels_changed = 0;  // of which changed state
  int64_t out_of_bounds = 0;   // observations dropped by the configured bounds
  map::KeyBox changed_bounds;  // bounding box of the changed voxels
};

namespace detail {
// One ray's walk from its end voxel to the camera's: Amanatides & Woo in 32.32 fixed point, so
// the loop-carried chain is integer compares and adds.
struct Walk {
  int64_t idx;            // current scratch cell
  int64_t tx, ty, tz;     // ray parameter at the next boundary on each axis
  int64_t dtx, dty, dtz;  // parameter step between boundaries
  int64_t sx, sy, sz;     // scratch index step on each axis
  int steps;              // boundaries left to cross
};
}  // namespace detail

class DepthIntegrator {
 public:
  explicit DepthIntegrator(const IntegrationParams& params);

  // Integrates one frame. Appends the state changes to *changes when given. A rejected frame
  // leaves the map untouched.
  IntegrationReport integrate(const DepthFrame& frame, OccupancyMap& map,
                              std::vector<map::VoxelChange>* changes);

  const IntegrationParams& params() const { return params_; }

 private:
  IntegrationParams params_;
  // Scratch reused across frames: a byte per voxel of the view frustum's bounding box, all-zero
  // between frames (cleared while applying), and per-image-row buffers.
  std::vector<uint8_t> marks_;
  std::vector<float> column_x_;
  std::vector<uint16_t> row_raw_;
  std::vector<uint8_t> row_kind_;
  std::vector<float> row_z_;
  std::vector<float> row_p_;
  std::vector<int32_t> row_idx_;
  std::vector<int32_t> row_quadrant_;
  std::vector<detail::Walk> walks_;
  std::vector<map::VoxelBlock*> block_table_;
};

// Why a frame cannot be integrated, or empty when it can. Exposed for the node's diagnostics.
std::string check_frame(const DepthFrame& frame);

}  // namespace semx::mapper
