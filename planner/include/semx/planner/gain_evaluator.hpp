// The geometric gain G(n) = w_n U_n + w_f U_f + w_s U_s of a viewpoint (paper Eq. 1, DEP's
// definition), per yaw bin, so each node gets the yaw whose camera window sees the most.
//
// Voxel kinds (disjoint; semx/map/state_grid.hpp, 6-connectivity):
//   surface  (U_s): unknown, a free face neighbour and an occupied face neighbour;
//   frontier (U_f): unknown, a free face neighbour, no occupied one;
//   unknown  (U_n): any other unknown voxel ("normal").
// Sensor model: a voxel counts when its centre c is within [min_range, max_range] of the node,
// within the vertical field of view that every image column has (|tan elevation| ≤
// tan(vfov/2)·cos(hfov/2), 28° for the default camera level with the body: conservative, so
// that flying to a node and looking along its yaw sees what it counted) and it is reached by
// a gain ray from the node before any occupied voxel (unknown space does not occlude: the
// optimistic assumption of DEP and NBVP). It goes to the yaw bin of its azimuth. A yaw window
// is `W = round(hfov / bin width)` consecutive bins (8 of 32 for the 90° camera); the node's gain
// is that of its best window and its yaw is the window's centre.
//
// Rays: rays_azimuth × rays_elevation directions, evenly spread around the node and across the
// vertical field of view, each walked voxel by voxel (3-D DDA) to max_range from the centre of the
// node's voxel (so the walks are computed once; the sector test and a voxel's azimuth bin use the
// node's own position, read from per-step tables where every position in the voxel gives the same
// answer); each voxel counts at most once per node. Rays sample the view: with the
// defaults (128 × 10) every voxel within about 2 m is reached, farther ones in part, so U counts
// the distinct voxels the rays reach.
// evaluate_exact() counts every visible voxel of the sector by enumeration (the reference of the
// tests; far too slow for planning). Voxels in the ignored set (what a visited goal still counted
// after the vehicle looked from it: unobservable, exploration_planner.hpp) count for nothing.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "semx/map/state_grid.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/planner/voxel_set.hpp"

namespace semx::planner {

enum class GainVoxel : uint8_t { kUnknown = 0, kFrontier = 1, kSurface = 2 };

// What one gain evaluation found.
struct NodeGain {
  std::vector<float> bin_gain;                    // weighted voxels per yaw bin
  std::vector<std::array<int32_t, 3>> bin_count;  // voxels per bin and kind (GainVoxel order)
  int best_window = 0;                            // first bin of the best window
  double gain = 0.0;                              // G at the best window
  double yaw = 0.0;                               // centre of the best window, rad
  std::array<int64_t, 3> counts{};                // U_n, U_f, U_s in the best window
  bool valid = false;

  int64_t total_voxels() const;  // over all bins
};

struct GainStats {
  int64_t evaluations = 0;
  int64_t rays = 0;
  int64_t steps = 0;  // voxels visited by rays
};

class GainEvaluator {
 public:
  explicit GainEvaluator(const GainConfig& config);

  const GainConfig& config() const { return config_; }
  int bins() const { return config_.yaw_bins; }
  int window_bins() const { return window_; }
  double bin_width() const;
  // Yaw at the centre of the window that starts at bin j.
  double window_yaw(int j) const;
  // Bin of an azimuth (rad).
  int bin_of(double azimuth) const;
  // The voxel's kind, or false when it is not unknown.
  static bool classify(map::StateGrid::Reader& r, const map::VoxelKey& k, GainVoxel& kind);

  // Ray-cast gain (the planner's). Not thread-safe (reuses a scratch bitset).
  NodeGain evaluate(const map::StateGrid& grid, const Eigen::Vector3d& p, GainStats* stats = nullptr);
  // As evaluate(), also listing the voxels counted in the window centred nearest to `yaw`.
  NodeGain evaluate(const map::StateGrid& grid, const Eigen::Vector3d& p, double yaw,
                    std::vector<map::VoxelKey>* counted, GainStats* stats = nullptr);
  // Voxels never to count (the unobservable ones, exploration_planner.hpp); null for none. Must
  // outlive the evaluator's use.
  void set_ignored(const VoxelSet* ignored) { ignored_ = ignored; }
  // Every voxel of the sector, each tested with its own line of sight (reference for tests).
  NodeGain evaluate_exact(const map::StateGrid& grid, const Eigen::Vector3d& p) const;

  // First bin of the window centred nearest to `yaw`.
  int window_of(double yaw) const;
  // Fills best_window, gain, yaw and counts from the bins.
  void finish(NodeGain& g) const;
  // Gain of the window centred nearest to `yaw`.
  double gain_at_yaw(const NodeGain& g, double yaw) const;
  // What a goal at `yaw` is worth to a vehicle now at `from_yaw`: with gain.sweep what the turn
  // sweeps on its way there (sweep_gain), else the window's gain (gain_at_yaw). DEP scores goals so.
  double goal_gain(const NodeGain& g, double from_yaw, double yaw) const;
  // What a camera turning at the node from `from_yaw` to the window starting at bin `to_window`,
  // the shorter way, sees: every bin of every window it passes, each once (all bins when the
  // turn and the window together span them). sweep_gains() fills this for every window at once.
  double sweep_gain(const NodeGain& g, double from_yaw, int to_window) const;
  void sweep_gains(const NodeGain& g, double from_yaw, std::vector<double>& out) const;
  // The sensor model's range and vertical field of view for a voxel centre at `offset` from the
  // camera (any azimuth: the yaw windows decide the horizontal field); FUEL's viewpoint coverage
  // uses it too, so both planners see with the same camera.
  bool in_sector(const Eigen::Vector3d& offset) const;

 private:
  // Bin of an offset's azimuth, starting the search from a guess (the ray's bin): exact, without
  // atan2 (cross products with the bins' boundary directions).
  int bin_near(const Eigen::Vector3d& offset, int guess) const;
  void add(NodeGain& g, int bin, GainVoxel kind) const;
  // The rays' voxel lists and the scratch bitset for this resolution.
  void prepare(double res);

  GainConfig config_;
  int window_ = 1;
  double tan_half_vfov_ = 0.0;
  std::vector<Eigen::Vector3d> directions_;
  std::vector<int> direction_bin_;             // bin of each direction's azimuth
  std::vector<Eigen::Vector2d> bin_boundary_;  // unit vector at the start of each bin
  // Each ray's voxels from the centre of the node's voxel, as offsets; ray r's at
  // [ray_begin_[r], ray_begin_[r+1]). Three arrays, so that the steps through free voxels (most
  // of them) read only the first: the offset packed as three biased fields (kField bits each),
  // added to the node's packed place in its block in one integer addition.
  struct RayStep {
    int16_t dx, dy, dz, pad;
  };
  // What an unknown voxel's step needs: its bit in seen_, and the sector test and azimuth bin
  // where they are the same wherever the node lies in its voxel (else computed, kTest / kNoBin).
  struct StepInfo {
    uint32_t bit;
    uint16_t bin;
    uint8_t sector;
    uint8_t pad;
  };
  enum : uint8_t { kOut = 0, kIn = 1, kTest = 2 };
  static constexpr uint16_t kNoBin = 0xFFFF;
  std::vector<uint64_t> step_packed_;
  std::vector<StepInfo> step_info_;
  std::vector<RayStep> ray_steps_;
  std::vector<uint32_t> ray_begin_;
  // Sector and bin of every point of the cube [o - h, o + h] (o a voxel's offset, h half a voxel
  // and a margin for rounding), or kTest / kNoBin when the cube straddles a boundary.
  uint8_t sector_of_cube(const Eigen::Vector3d& o, double h) const;
  uint16_t bin_of_cube(const Eigen::Vector3d& o, double h) const;
  // The blocks around the node's, looked up in this evaluation (block_stamp_ == stamp_).
  std::vector<const map::VoxelBlock*> block_ptr_;
  std::vector<const VoxelSet::Mask*> ignored_ptr_;  // the ignored voxels of the same blocks
  mutable std::vector<double> sweep_prefix_;
  std::vector<uint32_t> block_stamp_;
  uint32_t stamp_ = 0;
  int block_lo_ = 0, block_lo_z_ = 0, block_n_ = 0;
  // Scratch: one bit per voxel of the box around the node, "already counted".
  std::vector<uint64_t> seen_;
  std::vector<uint64_t> surface_;  // seen_ voxels that are surface voxels (surface_occludes)
  const VoxelSet* ignored_ = nullptr;
  double seen_res_ = 0.0;
  int hx_ = 0, hz_ = 0;
};

}  // namespace semx::planner
