// Messages for the controller node's tests, from the logic's plain data.
#pragma once

#include <semx/esdf_local_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>

#include <vector>

#include "semx/controller/grid_distance_field.hpp"

namespace semx::controller::test {

inline semx::esdf_local_t esdf_message(const GridDistanceField& f, int64_t utime) {
  semx::esdf_local_t m{};
  m.utime = utime;
  m.resolution = f.resolution();
  for (int a = 0; a < 3; ++a) m.origin[a] = f.origin()[a];
  m.nx = f.nx();
  m.ny = f.ny();
  m.nz = f.nz();
  m.max_distance = f.max_distance();
  m.unknown_as_occupied = 1;
  m.num_cells = m.nx * m.ny * m.nz;
  m.distance.resize(static_cast<std::size_t>(m.num_cells));
  for (int z = 0; z < m.nz; ++z)
    for (int y = 0; y < m.ny; ++y)
      for (int x = 0; x < m.nx; ++x) m.distance[f.index(x, y, z)] = f.value(x, y, z);
  return m;
}

inline semx::odometry_t odometry(const Eigen::Vector3d& p, int64_t utime) {
  semx::odometry_t m{};
  m.utime = utime;
  for (int a = 0; a < 3; ++a) m.position[a] = p[a];
  m.orientation[0] = 1.0;
  return m;
}

inline semx::path_t path_message(const std::vector<Eigen::Vector3d>& pts, int64_t id, int64_t utime,
                                 double yaw = 0.0) {
  semx::path_t m{};
  m.utime = utime;
  m.plan_id = id;
  m.num_waypoints = static_cast<int32_t>(pts.size());
  for (const auto& p : pts) {
    m.waypoints.push_back({p.x(), p.y(), p.z()});
    m.yaws.push_back(yaw);
  }
  return m;
}

}  // namespace semx::controller::test
