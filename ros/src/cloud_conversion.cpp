#include "semx/ros/cloud_conversion.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace semx::rosbridge {

namespace {

msg::PointCloud2 float_cloud(const std::vector<std::string>& names, const std::string& frame, int64_t stamp_ns,
                             std::size_t points) {
  msg::PointCloud2 c;
  c.header.stamp_ns = stamp_ns;
  c.header.frame_id = frame;
  uint32_t offset = 0;
  for (const auto& n : names) {
    c.fields.push_back({n, offset, msg::PointField::FLOAT32, 1});
    offset += 4;
  }
  c.point_step = offset;
  c.height = 1;
  c.width = static_cast<uint32_t>(points);
  c.row_step = c.point_step * c.width;
  c.data.resize(static_cast<std::size_t>(c.row_step));
  c.is_dense = true;
  return c;
}

void put(std::vector<uint8_t>& data, std::size_t at, float v) { std::memcpy(&data[at], &v, 4); }
float get(const std::vector<uint8_t>& data, std::size_t at) {
  float v;
  std::memcpy(&v, &data[at], 4);
  return v;
}

// Offsets of float32 fields `names` in `cloud`; false when one is missing or the sizes disagree.
bool float_offsets(const msg::PointCloud2& cloud, const std::vector<std::string>& names, std::vector<uint32_t>& at) {
  if (cloud.is_bigendian) return false;
  at.clear();
  for (const auto& n : names) {
    auto it = std::find_if(cloud.fields.begin(), cloud.fields.end(),
                           [&](const msg::PointField& f) { return f.name == n; });
    if (it == cloud.fields.end() || it->datatype != msg::PointField::FLOAT32 || it->count != 1 ||
        it->offset + 4 > cloud.point_step) {
      return false;
    }
    at.push_back(it->offset);
  }
  if (static_cast<std::size_t>(cloud.row_step) < static_cast<std::size_t>(cloud.point_step) * cloud.width) return false;
  return cloud.data.size() >= static_cast<std::size_t>(cloud.row_step) * cloud.height;
}

}  // namespace

msg::PointCloud2 voxel_cloud(const map::StateGrid& grid, map::VoxelState state, const std::string& frame,
                             int64_t stamp_ns, double max_z) {
  const double r = grid.resolution();
  std::vector<map::VoxelKey> keys;
  keys.reserve(static_cast<std::size_t>(state == map::VoxelState::kOccupied ? grid.occupied_voxels()
                                                                            : grid.free_voxels()));
  grid.for_each_block([&](const map::VoxelKey& b, const map::VoxelBlock& block) {
    if (block.known == 0) return;
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (block.state[static_cast<std::size_t>(i)] != state) continue;
      const map::VoxelKey k = map::voxel_of(b, i);
      if ((k.z + 0.5) * r <= max_z) keys.push_back(k);
    }
  });
  std::sort(keys.begin(), keys.end());
  msg::PointCloud2 c = float_cloud({"x", "y", "z"}, frame, stamp_ns, keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::size_t at = i * c.point_step;
    put(c.data, at, static_cast<float>((keys[i].x + 0.5) * r));
    put(c.data, at + 4, static_cast<float>((keys[i].y + 0.5) * r));
    put(c.data, at + 8, static_cast<float>((keys[i].z + 0.5) * r));
  }
  return c;
}

bool voxel_keys(const msg::PointCloud2& cloud, double resolution, std::vector<map::VoxelKey>& keys) {
  std::vector<uint32_t> at;
  if (!(resolution > 0) || !float_offsets(cloud, {"x", "y", "z"}, at)) return false;
  keys.clear();
  for (uint32_t row = 0; row < cloud.height; ++row) {
    for (uint32_t col = 0; col < cloud.width; ++col) {
      const std::size_t base = static_cast<std::size_t>(row) * cloud.row_step + static_cast<std::size_t>(col) * cloud.point_step;
      map::VoxelKey k;
      for (int a = 0; a < 3; ++a) {
        const double v = get(cloud.data, base + at[static_cast<std::size_t>(a)]);
        if (!std::isfinite(v)) return false;
        k[a] = static_cast<int32_t>(std::floor(v / resolution));
      }
      keys.push_back(k);
    }
  }
  return true;
}

msg::PointCloud2 esdf_slice(const map::EsdfGrid& grid, double z, const std::string& frame, int64_t stamp_ns) {
  if (grid.empty() || grid.nz <= 0) return float_cloud({"x", "y", "z", "intensity"}, frame, stamp_ns, 0);
  const double r = grid.resolution;
  int iz = static_cast<int>(std::floor(z / r)) - grid.origin.z;
  iz = std::clamp(iz, 0, grid.nz - 1);
  msg::PointCloud2 c = float_cloud({"x", "y", "z", "intensity"}, frame, stamp_ns,
                                   static_cast<std::size_t>(grid.nx) * static_cast<std::size_t>(grid.ny));
  std::size_t p = 0;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix, ++p) {
      const std::size_t at = p * c.point_step;
      put(c.data, at, static_cast<float>((grid.origin.x + ix + 0.5) * r));
      put(c.data, at + 4, static_cast<float>((grid.origin.y + iy + 0.5) * r));
      put(c.data, at + 8, static_cast<float>((grid.origin.z + iz + 0.5) * r));
      put(c.data, at + 12, grid.distance[grid.index(ix, iy, iz)]);
    }
  }
  return c;
}

bool slice_points(const msg::PointCloud2& cloud, std::vector<SlicePoint>& points) {
  std::vector<uint32_t> at;
  if (!float_offsets(cloud, {"x", "y", "z", "intensity"}, at)) return false;
  points.clear();
  for (uint32_t row = 0; row < cloud.height; ++row) {
    for (uint32_t col = 0; col < cloud.width; ++col) {
      const std::size_t base = static_cast<std::size_t>(row) * cloud.row_step + static_cast<std::size_t>(col) * cloud.point_step;
      SlicePoint s;
      for (int a = 0; a < 3; ++a) s.position[a] = get(cloud.data, base + at[static_cast<std::size_t>(a)]);
      s.distance = get(cloud.data, base + at[3]);
      points.push_back(s);
    }
  }
  return true;
}

}  // namespace semx::rosbridge
