// A Euclidean signed distance field over a box of voxels (what ESDF_LOCAL carries). Its values
// are esdf_distance.hpp's, computed by the mapper's EsdfBuilder.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semx/map/voxel_key.hpp"

namespace semx::map {

struct EsdfGrid {
  double resolution = 0.1;
  VoxelKey origin;  // key of the window's minimum-corner voxel; cell (x, y, z) is key origin + (x, y, z)
  int nx = 0, ny = 0, nz = 0;
  double max_distance = 0.0;
  bool unknown_as_occupied = true;
  int64_t map_seq = -1;         // map sequence the field was computed from; -1 before the first
  std::vector<float> distance;  // metres, index x + nx * (y + ny * z)

  bool empty() const { return distance.empty(); }
  size_t index(int x, int y, int z) const {
    return static_cast<size_t>(x) + static_cast<size_t>(nx) * (y + static_cast<size_t>(ny) * z);
  }
  // Minimum corner of the window, metres.
  Eigen::Vector3d origin_point() const {
    return {origin.x * resolution, origin.y * resolution, origin.z * resolution};
  }
  bool contains(const VoxelKey& k) const {
    return k.x >= origin.x && k.y >= origin.y && k.z >= origin.z && k.x < origin.x + nx &&
           k.y < origin.y + ny && k.z < origin.z + nz;
  }
  // Value of the voxel with key k; false when k is outside the window.
  bool voxel_distance(const VoxelKey& k, float* d) const;
  // The field at p (esdf_distance.hpp's trilinear_distance, the query every reader uses) and its
  // gradient (1/m). Within half a voxel of the window's faces the border values extend. False
  // when p is outside the window or not finite.
  bool interpolate(const Eigen::Vector3d& p, double* distance, Eigen::Vector3d* gradient = nullptr) const;
};

}  // namespace semx::map
