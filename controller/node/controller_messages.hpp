// The only place the controller meets LCM message structs: content checks for the node's
// subscriptions, and conversions between messages and the plain data of the logic library.
// Part of semx_controller_node, not of semx_controller.
#pragma once

#include <semx/control_cmd_t.hpp>
#include <semx/controller_status_t.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/trajectory_t.hpp>

#include "semx/controller/command.hpp"
#include "semx/controller/controller_status.hpp"
#include "semx/controller/grid_distance_field.hpp"
#include "semx/controller/path.hpp"
#include "semx/controller/trajectory.hpp"
#include "semx/controller/vehicle_state.hpp"

namespace semx::controller {

// Subscription `accept` predicates: messages the logic cannot even represent are malformed.
// A path's content (empty, NaN, jumps) is not judged here but by the controller, which
// reports REJECTED so the planner hears about it.
bool accept_path(const semx::path_t& m);
// Positive sizes, num_cells == nx*ny*nz (and the array that long), resolution and max_distance
// positive, every value finite.
bool accept_esdf(const semx::esdf_local_t& m);
// Finite values and a unit quaternion (within 1e-3).
bool accept_odometry(const semx::odometry_t& m);

Path to_path(const semx::path_t& m);
GridDistanceField to_distance_field(const semx::esdf_local_t& m, OutsideWindow outside);
VehicleState to_vehicle_state(const semx::odometry_t& m);

semx::control_cmd_t to_message(const Command& c, int64_t utime);
semx::controller_status_t to_message(const ControllerStatus& s, int64_t utime);
semx::trajectory_t to_message(const Trajectory& t, int64_t utime);
// The inverse of to_message(Trajectory): what a viewer or a test reads back.
Trajectory to_trajectory(const semx::trajectory_t& m);

}  // namespace semx::controller
