// The ESDF's one definition: what a voxel's value is, and how the field is read between voxel
// centres. The mapper computes the values (EsdfBuilder, ESDF_LOCAL), the controller reads them
// (GridDistanceField), and the planner computes the same values from the map's states where it
// needs them (CollisionChecker::esdf); all three go through this header, so the planner's
// clearance and the controller's are one quantity (tests/integration).
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace semx::map {

// The value of a voxel whose centre lies `centre_voxels` voxel lengths from the nearest obstacle
// voxel's centre: half a voxel less, in metres, so that it approximates the distance to the
// obstacle's face and changes sign across a boundary (inside an obstacle the builder negates the
// same quantity taken to the nearest non-obstacle voxel). T is float for the mapper's grids,
// double for the planner's queries.
template <class T>
constexpr T esdf_value(T centre_voxels, T resolution) {
  return (centre_voxels - T(0.5)) * resolution;
}

// Trilinear interpolation of a field given at voxel centres, and the interpolant's exact
// gradient (so an optimiser's gradient and the values it checks agree).
//
// u: the point in centre coordinates of the field's cells (cell i's centre at u = i), e.g.
//    (p - the box's minimum corner) / resolution - 0.5.
// n: cells per axis. Past the outermost centres (within the box's faces) the border value
//    extends, with zero slope; n[a] <= 0: the field has no border on that axis.
// at(x, y, z): the value of cell (x, y, z); called only for corners whose weight is not zero
//    when no gradient is asked for (a corner of weight zero cannot change the value).
// gradient: d value / d p, in value units per metre (inv_resolution = 1 / resolution).
template <class At>
double trilinear_distance(const double u[3], const int n[3], double inv_resolution, At&& at,
                          Eigen::Vector3d* gradient = nullptr) {
  int i0[3], i1[3];
  double w[3], slope[3];
  for (int a = 0; a < 3; ++a) {
    const double fl = std::floor(u[a]);
    const int lo = static_cast<int>(fl);
    if (n[a] > 0 && lo < 0) {
      i0[a] = i1[a] = 0;
      w[a] = 0.0;
      slope[a] = 0.0;
    } else if (n[a] > 0 && lo >= n[a] - 1) {
      i0[a] = i1[a] = n[a] - 1;
      w[a] = 0.0;
      slope[a] = 0.0;
    } else {
      i0[a] = lo;
      w[a] = u[a] - fl;
      // Without a gradient a corner of weight zero adds nothing: read its neighbour's value.
      i1[a] = (w[a] == 0.0 && !gradient) ? lo : lo + 1;
      slope[a] = inv_resolution;
    }
  }
  const double c000 = at(i0[0], i0[1], i0[2]);
  const bool x1 = i1[0] != i0[0], y1 = i1[1] != i0[1], z1 = i1[2] != i0[2];
  const double c100 = x1 ? at(i1[0], i0[1], i0[2]) : c000;
  const double c010 = y1 ? at(i0[0], i1[1], i0[2]) : c000;
  const double c110 = y1 ? (x1 ? at(i1[0], i1[1], i0[2]) : c010) : c100;
  const double c001 = z1 ? at(i0[0], i0[1], i1[2]) : c000;
  const double c101 = z1 ? (x1 ? at(i1[0], i0[1], i1[2]) : c001) : c100;
  const double c011 = z1 ? (y1 ? at(i0[0], i1[1], i1[2]) : c001) : c010;
  const double c111 = z1 ? (y1 ? (x1 ? at(i1[0], i1[1], i1[2]) : c011) : c101) : c110;
  const double wx = w[0], wy = w[1], wz = w[2];
  const double c00 = c000 + wx * (c100 - c000), c10 = c010 + wx * (c110 - c010);
  const double c01 = c001 + wx * (c101 - c001), c11 = c011 + wx * (c111 - c011);
  const double c0 = c00 + wy * (c10 - c00), c1 = c01 + wy * (c11 - c01);
  if (gradient) {
    const double dx0 = (1 - wy) * (c100 - c000) + wy * (c110 - c010);
    const double dx1 = (1 - wy) * (c101 - c001) + wy * (c111 - c011);
    (*gradient)[0] = ((1 - wz) * dx0 + wz * dx1) * slope[0];
    (*gradient)[1] = ((1 - wz) * (c10 - c00) + wz * (c11 - c01)) * slope[1];
    (*gradient)[2] = (c1 - c0) * slope[2];
  }
  return c0 + wz * (c1 - c0);
}

}  // namespace semx::map
