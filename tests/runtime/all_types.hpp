// Every generated semx type, for tests that must cover the whole contract.
#pragma once

#include <semx/ack_t.hpp>
#include <semx/camera_info_t.hpp>
#include <semx/channel_stats_t.hpp>
#include <semx/clock_t.hpp>
#include <semx/control_cmd_t.hpp>
#include <semx/controller_status_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/imu_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/map_request_t.hpp>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_stats_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/node_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/resend_t.hpp>
#include <semx/rgb_image_t.hpp>
#include <semx/roadmap_node_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_region_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/sim_event_t.hpp>
#include <semx/trajectory_t.hpp>

#define SEMX_ALL_TYPES(X)                                                                                 \
  X(ack_t)                                                                                                \
  X(camera_info_t) X(channel_stats_t) X(clock_t) X(control_cmd_t) X(controller_status_t) X(depth_image_t) \
      X(esdf_local_t) X(imu_t) X(label_image_t) X(map_request_t) X(map_snapshot_t) X(map_stats_t)         \
          X(map_update_t) X(node_status_t) X(odometry_t) X(path_t) X(planner_status_t) X(resend_t) X(rgb_image_t)     \
              X(roadmap_node_t) X(roadmap_t) X(semantic_region_t) X(semantic_regions_t) X(sim_event_t)    \
                  X(trajectory_t)
