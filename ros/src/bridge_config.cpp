#include "semx/ros/bridge_config.hpp"

namespace semx::rosbridge {

const char* to_string(BridgeMode m) { return m == BridgeMode::kExternal ? "external" : "mirror"; }

namespace {

void topic(runtime::ConfigMap& m, const std::string& key, std::string& value, bool may_be_empty = false) {
  m.get(key, value);
  if (value.empty() && !may_be_empty) m.fail(key, "a topic name is required");
  if (!value.empty() && value.find_first_of(" \t\n") != std::string::npos) m.fail(key, "topic names have no blanks");
}

}  // namespace

void load(runtime::ConfigMap& m, BridgeConfig& c) {
  std::string mode = to_string(c.mode);
  m.get_choice("mode", mode, {"mirror", "external"});
  c.mode = mode == "external" ? BridgeMode::kExternal : BridgeMode::kMirror;
  m.get("node_name", c.node_name);
  if (c.node_name.empty()) m.fail("node_name", "must not be empty");

  auto f = m.child("frames");
  const std::pair<const char*, std::string*> frame_keys[] = {
      {"map", &c.frames.map}, {"body", &c.frames.body}, {"camera", &c.frames.camera}, {"optical", &c.frames.optical}};
  for (const auto& [key, value] : frame_keys) {
    f.get(key, *value);
    if (value->empty()) f.fail(key, "a frame name is required");
  }

  auto o = m.child("out");
  topic(o, "odom", c.out.odom);
  topic(o, "map", c.out.map);
  topic(o, "map_free", c.out.map_free);
  topic(o, "esdf_slice", c.out.esdf_slice);
  topic(o, "roadmap", c.out.roadmap);
  topic(o, "regions", c.out.regions);
  topic(o, "path", c.out.path);
  topic(o, "trajectory", c.out.trajectory);
  topic(o, "planner_status", c.out.planner_status);
  topic(o, "depth", c.out.depth);
  topic(o, "depth_info", c.out.depth_info);
  topic(o, "labels", c.out.labels);
  topic(o, "labels_info", c.out.labels_info);
  topic(o, "rgb", c.out.rgb);
  topic(o, "rgb_info", c.out.rgb_info);

  auto i = m.child("in");
  topic(i, "odom", c.in.odom);
  i.get_choice("odom_type", c.in.odom_type, {"odometry", "pose"});
  topic(i, "depth", c.in.depth);
  topic(i, "camera_info", c.in.camera_info);
  topic(i, "labels", c.in.labels, true);
  i.get("min_range", c.in.min_range, 0.0, 100.0);
  i.get("max_range", c.in.max_range, 0.01, 100.0);
  if (c.in.max_range <= c.in.min_range) i.fail("max_range", "must exceed min_range");
  i.get("tf_timeout_s", c.in.tf_timeout_s, 0.0, 10.0);
  i.get("publish_body_tf", c.in.publish_body_tf);

  auto s = m.child("setpoints");
  s.get_choice("mode", c.setpoints.mode, {"velocity", "position", "both", "none"});
  topic(s, "velocity_topic", c.setpoints.velocity_topic);
  topic(s, "position_topic", c.setpoints.position_topic);
  s.get("yaw_gain", c.setpoints.conversion.yaw_gain, 0.0, 100.0);
  s.get("max_yaw_rate", c.setpoints.conversion.max_yaw_rate, 0.0, 20.0);
  s.get("lead_s", c.setpoints.conversion.lead_s, 0.0, 10.0);

  auto r = m.child("rates");
  r.get("map_hz", c.rates.map_hz, 0.01, 100.0);
  r.get("map_free_hz", c.rates.map_free_hz, 0.01, 100.0);
  r.get("esdf_hz", c.rates.esdf_hz, 0.01, 100.0);
  r.get("trajectory_dt", c.rates.trajectory_dt, 0.01, 10.0);
  r.get("esdf_slice_offset", c.rates.esdf_slice_offset, -10.0, 10.0);
  r.get("map_max_z", c.rates.map_max_z, -1e6, 1e6);

  m.get("camera", c.camera);
  m.get("publish_clock", c.publish_clock);
  m.get("queue_frames", c.queue_frames, 1, 1000);
  m.get("queue_messages", c.queue_messages, 1, 100000);
  m.get("master_check_s", c.master_check_s, 0.05, 60.0);
  m.get("clock_period_s", c.clock_period_s, 0.001, 1.0);
}

}  // namespace semx::rosbridge
