// The only place the bridge meets LCM message structs: content checks for the node's
// subscriptions, and conversions between semx's messages and the bridge library's values
// (bridge_values.hpp; the map's, the controller's and the camera's own conversions are reused).
// Part of semx_ros_node, not of semx_ros.
#pragma once

#include <semx/clock_t.hpp>
#include <semx/control_cmd_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/rgb_image_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/trajectory_t.hpp>

#include <string>
#include <vector>

#include "semx/ros/bridge_values.hpp"

namespace semx::rosbridge {

// Subscription `accept` predicates: finite values, consistent sizes, a usable camera.
bool accept_roadmap(const semx::roadmap_t& m);
bool accept_regions(const semx::semantic_regions_t& m);
bool accept_status(const semx::planner_status_t& m);
bool accept_command(const semx::control_cmd_t& m);
bool accept_trajectory(const semx::trajectory_t& m);
bool accept_camera(const semx::camera_info_t& info);

VehicleOdometry from_message(const semx::odometry_t& m);
semx::odometry_t to_message(const VehicleOdometry& o);

// Decoded frames; "" when the payload decodes to the image's size, else why not.
std::string from_message(const semx::depth_image_t& m, DepthFrame& out);
std::string from_message(const semx::label_image_t& m, LabelFrame& out);
std::string from_message(const semx::rgb_image_t& m, RgbFrame& out);
// Encoded as the simulator encodes them (depth raw, labels and RGB run-length).
semx::depth_image_t to_message(const DepthFrame& f);
semx::label_image_t to_message(const LabelFrame& f);

Roadmap from_message(const semx::roadmap_t& m);
std::vector<Region> from_message(const semx::semantic_regions_t& m);
PlannerStatus from_message(const semx::planner_status_t& m);
VehicleCommand from_message(const semx::control_cmd_t& m);

semx::clock_t clock_message(int64_t tick, int64_t utime, int64_t period_us);

}  // namespace semx::rosbridge
