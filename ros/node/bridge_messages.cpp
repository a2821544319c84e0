#include "bridge_messages.hpp"

#include <cmath>

#include "semx/runtime/camera_info.hpp"
#include "semx/runtime/image_codec.hpp"
#include "semx/runtime/roadmap_messages.hpp"

namespace semx::rosbridge {

namespace {

template <class T>
bool finite(const T& values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

Eigen::Vector3d vec(const double (&v)[3]) { return {v[0], v[1], v[2]}; }

CameraShot shot_of(const semx::camera_info_t& info, int64_t utime) {
  CameraShot s;
  s.utime = utime;
  s.frame_id = info.frame_id;
  runtime::from_camera_info(info, s.camera, s.T_world_optical);
  return s;
}

std::size_t pixels(const semx::camera_info_t& i) { return static_cast<std::size_t>(i.width) * i.height; }

}  // namespace

bool accept_camera(const semx::camera_info_t& info) {
  runtime::PinholeCamera camera;
  Eigen::Isometry3d pose;
  return runtime::from_camera_info(info, camera, pose).empty();
}

bool accept_roadmap(const semx::roadmap_t& m) {
  for (const auto& n : m.nodes) {
    if (!finite(n.position) || !std::isfinite(n.yaw)) return false;
  }
  return m.edge_from.size() == m.edge_to.size();
}

bool accept_regions(const semx::semantic_regions_t& m) {
  for (const auto& r : m.regions) {
    if (!finite(r.centroid) || !std::isfinite(r.radius) || r.radius < 0 || !finite(r.extent)) return false;
  }
  return true;
}

bool accept_status(const semx::planner_status_t& m) { return finite(m.goal); }

bool accept_command(const semx::control_cmd_t& m) {
  return finite(m.setpoint) && std::isfinite(m.yaw) && std::isfinite(m.yaw_rate) && m.mode >= 0 &&
         m.mode <= 2 && (m.yaw_mode == 0 || m.yaw_mode == 1);
}

bool accept_trajectory(const semx::trajectory_t& m) {
  if (m.degree != 3 || !(m.knot_interval > 0) || !std::isfinite(m.knot_interval)) return false;
  if (m.control_points.size() != m.yaw_control_points.size()) return false;
  for (const auto& p : m.control_points) {
    if (!finite(p)) return false;
  }
  return finite(m.yaw_control_points);
}

VehicleOdometry from_message(const semx::odometry_t& m) {
  VehicleOdometry o;
  o.utime = m.utime;
  o.position = vec(m.position);
  o.orientation =
      Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]).normalized();
  o.velocity = vec(m.velocity);
  o.angular_velocity = vec(m.angular_velocity);
  return o;
}

semx::odometry_t to_message(const VehicleOdometry& o) {
  semx::odometry_t m{};
  m.utime = o.utime;
  for (int i = 0; i < 3; ++i) {
    m.position[i] = o.position[i];
    m.velocity[i] = o.velocity[i];
    m.angular_velocity[i] = o.angular_velocity[i];
  }
  m.orientation[0] = o.orientation.w();
  m.orientation[1] = o.orientation.x();
  m.orientation[2] = o.orientation.y();
  m.orientation[3] = o.orientation.z();
  return m;
}

std::string from_message(const semx::depth_image_t& m, DepthFrame& out) {
  out.shot = shot_of(m.info, m.utime);
  return runtime::decode_u16_image(m.compression, m.depth_data, pixels(m.info), out.depth_mm);
}

std::string from_message(const semx::label_image_t& m, LabelFrame& out) {
  out.shot = shot_of(m.info, m.utime);
  const std::size_t n = pixels(m.info);
  std::vector<uint8_t> raw;
  std::string error;
  if (!runtime::decode_image(m.label_compression, m.label_data, 4 * n, raw, &error)) return error;
  out.classes.resize(n);
  out.instances.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const uint8_t* p = raw.data() + 4 * i;
    out.classes[i] = static_cast<uint16_t>(p[0] | (p[1] << 8));
    out.instances[i] = static_cast<uint16_t>(p[2] | (p[3] << 8));
  }
  return "";
}

std::string from_message(const semx::rgb_image_t& m, RgbFrame& out) {
  out.shot = shot_of(m.info, m.utime);
  std::string error;
  if (!runtime::decode_image(m.rgb_compression, m.rgb_data, 3 * pixels(m.info), out.rgb, &error))
    return error;
  return "";
}

semx::depth_image_t to_message(const DepthFrame& f) {
  return runtime::depth_image_message(f.shot.camera, f.shot.T_world_optical, f.depth_mm.data(),
                                      f.depth_mm.size(), f.shot.utime, f.shot.frame_id,
                                      runtime::ImageCompression::kNone);
}

semx::label_image_t to_message(const LabelFrame& f) {
  semx::label_image_t m{};
  m.utime = f.shot.utime;
  m.info = runtime::to_camera_info(f.shot.camera, f.shot.T_world_optical, f.shot.frame_id);
  std::vector<uint8_t> raw(4 * f.classes.size());
  for (std::size_t i = 0; i < f.classes.size(); ++i) {
    const uint16_t c = f.classes[i], k = i < f.instances.size() ? f.instances[i] : 0;
    raw[4 * i] = static_cast<uint8_t>(c & 0xFF);
    raw[4 * i + 1] = static_cast<uint8_t>(c >> 8);
    raw[4 * i + 2] = static_cast<uint8_t>(k & 0xFF);
    raw[4 * i + 3] = static_cast<uint8_t>(k >> 8);
  }
  runtime::ImageCompression used;
  m.label_data = runtime::encode_image(raw, 4, runtime::ImageCompression::kRle, used);
  m.label_compression = static_cast<int8_t>(used);
  m.num_label_bytes = static_cast<int32_t>(m.label_data.size());
  return m;
}

Roadmap from_message(const semx::roadmap_t& m) { return runtime::roadmap_from(m); }

std::vector<Region> from_message(const semx::semantic_regions_t& m) { return runtime::regions_from(m); }

PlannerStatus from_message(const semx::planner_status_t& m) {
  PlannerStatus s;
  s.utime = m.utime;
  s.planner = m.planner;
  s.state = m.state;
  s.reason = m.reason;
  s.iteration = m.iteration;
  s.num_nodes = m.num_nodes;
  s.num_edges = m.num_edges;
  s.goal = vec(m.goal);
  s.best_gain = m.best_gain;
  s.best_reward = m.best_reward;
  s.best_score = m.best_score;
  s.total_ms = m.total_ms;
  s.charged_s = m.charged_s;
  return s;
}

VehicleCommand from_message(const semx::control_cmd_t& m) {
  VehicleCommand c;
  c.utime = m.utime;
  c.mode = static_cast<VehicleCommand::Mode>(m.mode);
  c.setpoint = vec(m.setpoint);
  c.yaw_mode = static_cast<VehicleCommand::YawMode>(m.yaw_mode);
  c.yaw = m.yaw;
  c.yaw_rate = m.yaw_rate;
  return c;
}

semx::clock_t clock_message(int64_t tick, int64_t utime, int64_t period_us) {
  semx::clock_t m{};
  m.utime = utime;
  m.tick = tick;
  m.mode = semx::clock_t::REALTIME;
  m.speed = 1.0;
  m.period_us = period_us;
  return m;
}

}  // namespace semx::rosbridge
