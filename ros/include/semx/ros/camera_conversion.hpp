// The camera: semx's depth, label and RGB frames <-> sensor_msgs/Image + CameraInfo, and the
// camera's mount as a transform.
//
// Depth goes out as "16UC1" in millimetres (REP 118), with semx's two reserved values kept:
// 0 = no measurement, 65535 = nothing within max range. It comes in as "16UC1"/"mono16" (mm, the
// same two values) or "32FC1" (m; NaN, 0 and -Inf: no measurement, +Inf: no return, REP 118).
// Labels go out as "16UC2" (class id, instance id per pixel: semx's vocabulary,
// runtime/semantic_classes.hpp) and come in as "16UC2", or class ids alone as "16UC1"/"mono16"/
// "8UC1"/"mono8". RGB goes out as "rgb8". CameraInfo is a pinhole with no distortion; images
// with distortion are refused (semx's camera model has none: rectify first, e.g. image_proc).
// Ranges are not in CameraInfo: the bridge's config gives them for incoming images.
#pragma once

#include <string>

#include "semx/ros/bridge_values.hpp"
#include "semx/ros/frames.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

msg::CameraInfo to_ros_info(const CameraShot& shot, const FrameNames& frames, const TimeBase& time);
msg::Image to_ros(const DepthFrame& f, const FrameNames& frames, const TimeBase& time);
msg::Image to_ros(const LabelFrame& f, const FrameNames& frames, const TimeBase& time);
msg::Image to_ros(const RgbFrame& f, const FrameNames& frames, const TimeBase& time);

// The camera model of a CameraInfo, with the given range limits; "" when usable.
std::string camera_from_ros(const msg::CameraInfo& info, double min_range, double max_range,
                            runtime::PinholeCamera& camera);

// Incoming frames. `shot` carries the capture (model, pose, frame id, utime) the caller
// established from the CameraInfo, the TF tree and the stamp; the image must match its size.
// "" when usable, else why not (encoding, size, step).
std::string from_ros(const msg::Image& image, const CameraShot& shot, DepthFrame& out);
std::string from_ros(const msg::Image& image, const CameraShot& shot, LabelFrame& out);
std::string from_ros(const msg::Image& image, const CameraShot& shot, RgbFrame& out);

// The camera's mount: base_link -> camera_link at the capture (from the body's pose at the same
// instant), and the fixed camera_link -> optical rotation.
msg::TransformStamped camera_transform(const CameraShot& shot, const Eigen::Isometry3d& T_world_body,
                                       const FrameNames& frames, const TimeBase& time);
msg::TransformStamped optical_transform(const FrameNames& frames, int64_t stamp_ns);

}  // namespace semx::rosbridge
