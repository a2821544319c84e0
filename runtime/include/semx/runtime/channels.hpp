// Every LCM channel of semx and the one message type it carries (DESIGN.md §2,
// docs/messages.md). Channels are UPPER_SNAKE; one type per channel, so a tool that knows the
// channel knows how to validate and decode its bytes.
#pragma once

#include <string_view>

// X(CHANNEL, type) for every channel, in data-flow order.
#define SEMX_CHANNELS(X)                    \
  X(SIM_CLOCK, clock_t)                     \
  X(SIM_ACK, ack_t)                         \
  X(SIM_RESEND, resend_t)                   \
  X(SIM_EVENT, sim_event_t)                 \
  X(ODOMETRY, odometry_t)                   \
  X(IMU, imu_t)                             \
  X(CAMERA_DEPTH, depth_image_t)            \
  X(CAMERA_RGB, rgb_image_t)                \
  X(CAMERA_LABELS, label_image_t)           \
  X(CONTROL_CMD, control_cmd_t)             \
  X(MAP_UPDATE, map_update_t)               \
  X(MAP_SNAPSHOT, map_snapshot_t)           \
  X(MAP_REQUEST, map_request_t)             \
  X(MAP_STATS, map_stats_t)                 \
  X(ESDF_LOCAL, esdf_local_t)               \
  X(SEMANTIC_REGIONS, semantic_regions_t)   \
  X(ROADMAP, roadmap_t)                     \
  X(PLAN_PATH, path_t)                      \
  X(PLANNER_STATUS, planner_status_t)       \
  X(TRAJECTORY, trajectory_t)               \
  X(CONTROLLER_STATUS, controller_status_t) \
  X(NODE_STATUS, node_status_t)

namespace semx::channels {

#define SEMX_DECLARE_CHANNEL(name, type) inline constexpr const char* name = #name;
SEMX_CHANNELS(SEMX_DECLARE_CHANNEL)
#undef SEMX_DECLARE_CHANNEL

struct ChannelInfo {
  std::string_view channel;
  std::string_view type;  // fully qualified LCM type name
};

inline constexpr ChannelInfo kAll[] = {
#define SEMX_CHANNEL_INFO(name, type) {#name, "semx." #type},
    SEMX_CHANNELS(SEMX_CHANNEL_INFO)
#undef SEMX_CHANNEL_INFO
};

// The type carried on `channel`, or an empty view for a channel semx does not define.
inline std::string_view type_of(std::string_view channel) {
  for (const auto& c : kAll) {
    if (c.channel == channel) return c.type;
  }
  return {};
}

}  // namespace semx::channels
