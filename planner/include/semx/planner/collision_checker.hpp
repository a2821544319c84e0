// Collision checks of roadmap nodes and edges against the map, in the controller's own measure
// of clearance (docs/planner.md, "Collisions and the controller's contract"): esdf(p) is the ESDF
// value the controller would read at p (voxel-centre distances minus half a voxel, trilinear),
// with unknown voxels counted as obstacles.
//
//   node_free(p):    no occupied or unknown voxel overlaps the vehicle box grown by `margin`
//                    (0.35 × 0.35 × 0.25 m half sizes) and esdf(p) >= `clearance` (0.45 m);
//   passage_free(p): a passage node in a doorway: the bare body box is free and esdf(p) >=
//                    `door_clearance` (0.34 m);
//   edge_free(a, b): every point of the segment (not only samples) keeps `passage_clearance`
//                    (0.42 m), except at most `door_length` (1 m) that keeps door_clearance to
//                    occupied voxels and kDoorUnknownClearance to unknown ones: what the
//                    controller's dense check requires (0.32 m + 0.017 m pad) holds all along;
//   root_edge_free(root, b): edge_free when the root itself is node_free; otherwise points within
//                    root_escape_radius of the root are checked with the bare vehicle box against
//                    occupied voxels only, or, where that box overlaps one, with the ESDF: no
//                    closer than the root, farther than the half width (a root below the half
//                    width: rising from its own value by kContactRise per metre): the vehicle may
//                    leave a pose whose surroundings are not mapped yet (the camera never sees the
//                    cone above and below itself), that drifted close to a wall or that touched one.
//
// The centre line is first walked voxel by voxel (no occupied or unknown voxel on it), which
// rejects edges through walls and into unknown space for the price of one ray.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

class CollisionChecker {
 public:
  explicit CollisionChecker(const CollisionConfig& config);

  void set_grid(const map::StateGrid* grid) { grid_ = grid; }
  const map::StateGrid* grid() const { return grid_; }
  // Half sizes of the box that bounds everything node_free() looks at.
  const Eigen::Vector3d& half_extent() const { return reach_; }

  bool node_free(const Eigen::Vector3d& p) const;
  bool passage_free(const Eigen::Vector3d& p) const;
  bool edge_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  bool root_edge_free(const Eigen::Vector3d& root, const Eigen::Vector3d& b) const;
  // The bare vehicle box at p overlaps no occupied voxel (unknown allowed).
  bool vehicle_free(const Eigen::Vector3d& p) const;
  // No occupied voxel (or unknown, when unknown_is_occupied) overlaps the open box p ± half.
  bool box_free(const Eigen::Vector3d& p, const Eigen::Vector3d& half, bool unknown_is_occupied) const {
    return region_free(p, half, 0.0, unknown_is_occupied);
  }
  // The controller's ESDF value at p as it would read it on this map with unknown voxels counted
  // as obstacles (the mapper's definition: centre-to-centre distance to the nearest obstacle voxel
  // minus half a voxel, at voxel centres; trilinear between them). Exact up to `cap`; above it a
  // lower bound >= cap. Never more than the controller reads, whose field ignores unknown space.
  double esdf(const Eigen::Vector3d& p, double cap, bool unknown_is_obstacle = true) const;
  // The largest cap esdf() serves from its cache; a larger one searches around every corner
  // (a cube of ~20k voxels at 1 m), which made one doorway's approach nodes cost ~1 ms.
  double cached_cap() const { return cache_cap_; }
  // m: spacing of the edge points checked where the coarse (edge_step) points fall short.
  static constexpr double kFineStep = 0.01;
  // m: in doorways, ESDF distance kept from unknown voxels (the body's half width + 5 cm; the
  // controller does not see them, door_clearance applies to occupied ones).
  static constexpr double kDoorUnknownClearance = 0.3;
  // m: how much closer to the obstacles than the root a point within root_escape_radius may be
  // when its bare box overlaps an occupied voxel (the controller's escape_slack).
  static constexpr double kEscapeSlack = 0.01;
  // m per m: how fast a root below the half width must move away from the obstacles within
  // root_escape_radius (the controller's contact_rise: 30° or more off the obstacle's surface).
  static constexpr double kContactRise = 0.5;
  // Moves p away from the occupied and unknown voxels within `clearance` of it (each pushes by
  // how much it intrudes, along the line from its cube's nearest point), up to `iterations` times
  // and by at most max_step each; true when p ends node_free (passage_free with `passage`).
  // Centres a draw that fell too close to a wall, and in a doorway between both jambs, so narrow
  // passages get nodes and edges.
  bool centre(Eigen::Vector3d& p, int iterations = 3, double max_step = 0.3, bool passage = false) const;

  // The grid changed at these voxels and nowhere else since the checker last looked: cached ESDF
  // values near them are dropped, the rest kept. When the grid made more transitions than there
  // are changes (it was replaced, or a delta was not passed on), the whole cache is dropped.
  void note_changes(const std::vector<map::VoxelChange>& changes) const;

  // Centre values are cached in chunks of kChunkSize^3 voxels, each filled at once.
  static constexpr int kChunkBits = 3;
  static constexpr int kChunkSize = 1 << kChunkBits;
  static constexpr int kChunkMask = kChunkSize - 1;
  static constexpr int kChunkVolume = kChunkSize * kChunkSize * kChunkSize;

  // Box checks made so far (for the planning-time charge); reset by the caller.
  int64_t box_checks() const { return box_checks_; }
  void reset_counters() const { box_checks_ = 0; }

 private:
  // No voxel (occupied, or unknown when unknown_is_occupied) overlaps the open box p ± half nor,
  // when radius > 0, has its cube within `radius` of p.
  bool region_free(const Eigen::Vector3d& p, const Eigen::Vector3d& half, double radius,
                   bool unknown_is_occupied) const;
  // No obstacle voxel in the box p ± half and esdf(p) >= distance.
  bool clear(const Eigen::Vector3d& p, const Eigen::Vector3d& half, double distance) const;
  bool centre_line_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double skip_radius) const;
  bool samples_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double escape_radius) const;

  CollisionConfig config_;
  Eigen::Vector3d body_half_;     // vehicle box + margin
  Eigen::Vector3d vehicle_half_;  // bare vehicle box
  Eigen::Vector3d reach_;         // max(body_half_, clearance) per axis
  // The ESDF at one voxel centre (before trilinear interpolation), exact below cache_cap_ +
  // a voxel diagonal + half a voxel and a lower bound above; cached until the grid changes.
  double centre_value(const map::VoxelKey& c, bool unknown_is_obstacle) const;
  using CacheChunk = std::array<double, kChunkVolume>;
  void fill_chunk(const map::VoxelKey& chunk, bool unknown_is_obstacle, CacheChunk& out) const;
  // The same, uncached, searching `reach` voxels around c.
  double centre_search(const map::VoxelKey& c, int reach, bool unknown_is_obstacle) const;
  static int reach_for(double cap, double res);
  void validate_cache() const;

  const map::StateGrid* grid_ = nullptr;
  mutable int64_t box_checks_ = 0;
  // Edge points 0.1 m and 0.01 m apart share most of their 8 corner centres, and edges share
  // them with their neighbours: caching the centres' values instead of searching around every
  // point made the cycle ~10x cheaper (semx-perf-planner). Keyed per unknown rule.
  double cache_cap_ = 0.0;
  mutable std::unordered_map<uint64_t, CacheChunk> centre_cache_[2];
  // The chunk read last, per unknown rule: a pointer into centre_cache_ (stable until an erase
  // or clear, which reset it); a copied checker starts without one, its cache being a copy.
  struct LastChunk {
    uint64_t key = 0;
    const CacheChunk* values = nullptr;
    LastChunk() = default;
    LastChunk(const LastChunk&) {}
    LastChunk& operator=(const LastChunk&) {
      values = nullptr;
      return *this;
    }
  };
  mutable std::array<LastChunk, 2> last_chunk_{};
  struct FillScratch {
    std::vector<uint64_t> rows;  // obstacle bits per row of the region
    std::vector<uint8_t> row_near, plane_near;
    // Squared distances in voxels, below 3 reach^2 <= 3 * 28^2 (rows of at most 64 voxels; each
    // pass adds one axis's square below reach^2): 16 bits, so that SSE2's 16-bit minimum takes
    // eight at once (it has none for 32 bits).
    std::vector<int16_t> gx, gy;
  };
  mutable FillScratch fill_scratch_;
  mutable const map::StateGrid* cache_grid_ = nullptr;
  mutable std::array<uint64_t, 4> cache_stamp_{};
};

}  // namespace semx::planner
