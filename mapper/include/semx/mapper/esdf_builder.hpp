// Computes the Euclidean signed distance field over a window around the vehicle (ESDF_LOCAL).
//
// Obstacle voxels are the occupied ones, plus the unknown ones when unknown_as_occupied. A voxel's
// value is map::esdf_value (semx/map/esdf_distance.hpp) of the distance from its centre to the
// nearest obstacle voxel's centre; inside obstacles, minus that of the distance to the nearest
// non-obstacle voxel. Values are clamped to +-max_distance. Only voxels inside the window
// are considered: an obstacle just outside it is not seen, so distances near the window border
// are upper bounds (the window is centred on the vehicle, where the field matters).
//
// Computed exactly over the whole window whenever it moved or a state inside it changed: outside
// obstacles by Felzenszwalb & Huttenlocher's lower envelope of parabolas, one pass per axis;
// inside them by a search around each voxel not on an obstacle's surface, or, when those are
// too many (thick unknown space counted as an obstacle), by the same transform.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/map/esdf_grid.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/mapper/mapper_config.hpp"

namespace semx::mapper {

// Scratch of squared_edt, kept between windows so that a recompute allocates nothing: a gathered
// line, its transform, and the lower envelope (sample index, its value plus index squared, and
// the left intersection as the fraction zn / zd).
struct EdtWorkspace {
  std::vector<float> line_in, line_out;
  std::vector<int> v;
  std::vector<int64_t> fv, zn, zd;
};

class EsdfBuilder {
 public:
  EsdfBuilder(const EsdfParams& params, double resolution);

  // Recomputes the field over the window centred on `center` when the window moved, `changed`
  // (voxels whose state changed since the last call) intersects it, or `force`. Returns whether
  // it recomputed.
  bool update(const map::StateGrid& grid, const Eigen::Vector3d& center, const map::KeyBox& changed,
              int64_t map_seq, bool force = false);
  const map::EsdfGrid& grid() const { return grid_; }
  const EsdfParams& params() const { return params_; }
  // Whether the last computation found the inside distances with the full transform (too many
  // voxels deep inside obstacles for the search); for tests and benchmarks.
  bool last_inside_transform() const { return last_inside_transform_; }
  // The search's budget, in voxel visits per window voxel, past which it gives way to the full
  // transform (the same values either way); 0 = always the transform. Benchmarks compare them.
  static constexpr double kDefaultSearchBudget = 8.0;
  void set_inside_search_budget(double visits_per_voxel) { search_budget_ = visits_per_voxel; }
  // Window placement for a vehicle at `center` (exposed for tests and the node).
  map::VoxelKey window_origin(const Eigen::Vector3d& center) const;

 private:
  void compute(const map::StateGrid& grid);
  // neg_ = squared distance to the nearest non-obstacle voxel, for the obstacle voxels only.
  void inside_distances();
  // The same for every voxel by the full transform (sites: the non-obstacle voxels).
  void inside_transform();

  EsdfParams params_;
  map::EsdfGrid grid_;
  std::vector<uint8_t> obstacle_;
  std::vector<float> pos_, neg_;
  EdtWorkspace edt_work_;
  std::vector<uint32_t> deep_;  // obstacle voxels with no non-obstacle face neighbour
  bool last_inside_transform_ = false;
  double search_budget_ = kDefaultSearchBudget;
};

// Squared Euclidean distance transform, in voxel units, of a dense nx*ny*nz grid (x fastest):
// out[i] = squared distance from cell i to the nearest cell with site[i] == want, or a value
// >= kEdtInfinity when there is none. Exposed for tests.
inline constexpr float kEdtInfinity = 1.0e18f;
void squared_edt(const uint8_t* site, uint8_t want, int nx, int ny, int nz, float* out, EdtWorkspace& work);

}  // namespace semx::mapper
