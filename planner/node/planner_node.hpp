// The planner process around the logic (docs/planner.md, "The node"): the map client keeps a copy
// of the mapper's map, the subscriptions feed the ExplorationPlanner, and each SIM_CLOCK tick runs
// its main loop and publishes what it released.
//
//   subscribes  MAP_UPDATE, MAP_SNAPSHOT (MapClient; sends MAP_REQUEST), ODOMETRY,
//               SEMANTIC_REGIONS, CONTROLLER_STATUS, SIM_CLOCK
//   publishes   PLAN_PATH (per new goal), ROADMAP (per cycle), PLANNER_STATUS (per cycle, on
//               change, and again every status_period_s of message time)
#pragma once

#include <cstdint>
#include <memory>

#include "map_client.hpp"
#include "semx/planner/exploration_planner.hpp"
#include "semx/planner/planner_config.hpp"
#include "semx/planner/truth_map.hpp"
#include "semx/runtime/node.hpp"

namespace semx::planner {

class PlannerNode {
 public:
  PlannerNode(runtime::NodeOptions options, const PlannerConfig& config);

  runtime::Node& node() { return node_; }
  ExplorationPlanner& planner() { return planner_; }
  const map::MapClient& map() const { return *map_; }
  int run() { return node_.run(); }
  // The world's ground truth for the known-map oracle (--world); the other planners ignore it.
  void set_truth(std::shared_ptr<const TruthMap> truth);

  // One tick of simulation time (what SIM_CLOCK triggers); public for tests.
  void on_tick(int64_t tick, int64_t utime);

  // PLANNER_STATUS is repeated this often (message time) so late listeners learn the state.
  static constexpr double kStatusPeriodS = 1.0;

 private:
  void update_node_state();

  PlannerConfig config_;
  runtime::Node node_;
  std::unique_ptr<map::MapClient> map_;
  std::shared_ptr<const TruthMap> truth_;
  ExplorationPlanner planner_;
  int64_t last_utime_ = -1;
  int64_t last_status_utime_ = -1;
  int64_t deferred_cycle_utime_ = -1;  // a cycle due at this tick runs after its ack
  PlannerState reported_state_ = PlannerState::kInit;
  bool oracle_reported_ = false;  // the oracle's plan was written to the log
};

}  // namespace semx::planner
