#include "controller_messages.hpp"

#include <cmath>

#include "semx/core/angles.hpp"

namespace semx::controller {
namespace {

template <class T>
bool all_finite(const T* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

bool accept_path(const semx::path_t& m) {
  if (m.num_waypoints < 0 || m.waypoints.size() != static_cast<std::size_t>(m.num_waypoints) ||
      m.yaws.size() != static_cast<std::size_t>(m.num_waypoints)) {
    return false;
  }
  for (const auto& w : m.waypoints) {
    if (w.size() != 3) return false;
  }
  return true;
}

bool accept_esdf(const semx::esdf_local_t& m) {
  if (m.nx <= 0 || m.ny <= 0 || m.nz <= 0) return false;
  const int64_t cells = static_cast<int64_t>(m.nx) * m.ny * m.nz;
  if (cells != m.num_cells || m.distance.size() != static_cast<std::size_t>(cells)) return false;
  if (!(m.resolution > 0) || !std::isfinite(m.resolution)) return false;
  if (!(m.max_distance > 0) || !std::isfinite(m.max_distance)) return false;
  if (!all_finite(m.origin, 3)) return false;
  return GridDistanceField::all_finite(m.distance.data(), m.distance.size());
}

bool accept_odometry(const semx::odometry_t& m) {
  if (!all_finite(m.position, 3) || !all_finite(m.orientation, 4) || !all_finite(m.velocity, 3) ||
      !all_finite(m.angular_velocity, 3)) {
    return false;
  }
  const double n2 = m.orientation[0] * m.orientation[0] + m.orientation[1] * m.orientation[1] +
                    m.orientation[2] * m.orientation[2] + m.orientation[3] * m.orientation[3];
  return std::abs(n2 - 1.0) < 2e-3;
}

Path to_path(const semx::path_t& m) {
  Path p;
  p.utime = m.utime;
  p.plan_id = m.plan_id;
  p.max_speed = m.max_speed;
  const std::size_t n = std::min(m.waypoints.size(), m.yaws.size());
  for (std::size_t i = 0; i < n; ++i) {
    p.waypoints.emplace_back(m.waypoints[i][0], m.waypoints[i][1], m.waypoints[i][2]);
    p.yaws.push_back(m.yaws[i]);
  }
  return p;
}

GridDistanceField to_distance_field(const semx::esdf_local_t& m, OutsideWindow outside) {
  return GridDistanceField(Eigen::Vector3d(m.origin[0], m.origin[1], m.origin[2]), m.resolution, m.nx, m.ny,
                           m.nz, m.distance, m.max_distance, outside);
}

VehicleState to_vehicle_state(const semx::odometry_t& m) {
  VehicleState s;
  s.utime = m.utime;
  s.position = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
  s.velocity = Eigen::Vector3d(m.velocity[0], m.velocity[1], m.velocity[2]);
  s.yaw = core::yaw_of_quaternion(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  return s;
}

semx::control_cmd_t to_message(const Command& c, int64_t utime) {
  semx::control_cmd_t m{};
  m.utime = utime;
  const bool velocity = c.mode == Command::Mode::kVelocity;
  m.mode = velocity ? semx::control_cmd_t::VELOCITY : semx::control_cmd_t::HOLD;
  for (int a = 0; a < 3; ++a) m.setpoint[a] = velocity ? c.velocity[a] : 0.0;
  m.yaw_mode = semx::control_cmd_t::YAW_ANGLE;
  m.yaw = core::wrap_angle(c.yaw);
  m.yaw_rate = c.yaw_rate;
  return m;
}

semx::controller_status_t to_message(const ControllerStatus& s, int64_t utime) {
  semx::controller_status_t m{};
  m.utime = utime;
  m.plan_id = s.plan_id;
  m.state = static_cast<int8_t>(s.state);
  m.reason = s.reason;
  m.tracking_error = s.tracking_error;
  m.tracking_rms = s.tracking_rms;
  m.progress = s.progress;
  return m;
}

semx::trajectory_t to_message(const Trajectory& t, int64_t utime) {
  semx::trajectory_t m{};
  m.utime = utime;
  m.plan_id = t.plan_id;
  m.start_utime = t.start_utime;
  m.degree = PositionSpline::kDegree;
  m.knot_interval = t.knot_interval();
  const auto& q = t.position.control_points();
  const auto& y = t.yaw.control_points();
  m.num_control_points = static_cast<int32_t>(q.size());
  m.control_points.resize(q.size());
  m.yaw_control_points.resize(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    m.control_points[i] = {q[i].x(), q[i].y(), q[i].z()};
    m.yaw_control_points[i] = i < y.size() ? y[i](0) : 0.0;
  }
  m.optimized = t.optimized;
  return m;
}

Trajectory to_trajectory(const semx::trajectory_t& m) {
  Trajectory t;
  t.plan_id = m.plan_id;
  t.start_utime = m.start_utime;
  t.optimized = m.optimized;
  PositionSpline::Points q;
  YawSpline::Points y;
  for (std::size_t i = 0; i < m.control_points.size() && i < m.yaw_control_points.size(); ++i) {
    q.emplace_back(m.control_points[i][0], m.control_points[i][1], m.control_points[i][2]);
    YawSpline::Point p;
    p(0) = m.yaw_control_points[i];
    y.push_back(p);
  }
  t.position = PositionSpline(std::move(q), m.knot_interval);
  t.yaw = YawSpline(std::move(y), m.knot_interval);
  return t;
}

}  // namespace semx::controller
