// The map as sensor_msgs/PointCloud2: the centres of the voxels in one state (x, y, z float32,
// in the map frame), and a horizontal slice of the ESDF window (x, y, z, intensity = signed
// distance in m). Float32 holds a voxel centre to well under a millimetre within a few km of the
// origin, so the voxel keys read back exactly.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "semx/map/esdf_grid.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

// Every voxel of `grid` in `state` whose centre is at most `max_z` high, in ascending key order.
msg::PointCloud2 voxel_cloud(const map::StateGrid& grid, map::VoxelState state, const std::string& frame,
                             int64_t stamp_ns, double max_z = std::numeric_limits<double>::infinity());
// The keys of a voxel_cloud (any cloud with float32 x, y, z), at `resolution`. False when the
// cloud lacks those fields or its sizes disagree.
bool voxel_keys(const msg::PointCloud2& cloud, double resolution, std::vector<map::VoxelKey>& keys);

struct SlicePoint {
  Eigen::Vector3f position;
  float distance;
};
// The window's layer of cells containing height z (the nearest layer when z is outside it).
msg::PointCloud2 esdf_slice(const map::EsdfGrid& grid, double z, const std::string& frame, int64_t stamp_ns);
// Reads back a cloud with float32 x, y, z, intensity; false when malformed.
bool slice_points(const msg::PointCloud2& cloud, std::vector<SlicePoint>& points);

}  // namespace semx::rosbridge
