#include "planner_node.hpp"

#include <algorithm>
#include <iostream>
#include <string>

#include "planner_messages.hpp"
#include "semx/planner/oracle_strategy.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::planner {

namespace {
constexpr int64_t kStatusPeriodUs = static_cast<int64_t>(PlannerNode::kStatusPeriodS * 1e6);
}  // namespace

PlannerNode::PlannerNode(runtime::NodeOptions options, const PlannerConfig& config)
    : config_(config), node_(std::move(options)), planner_(config) {
  // The map client registers its tick handler first, so the mirror is current when ours runs.
  map_ = std::make_unique<map::MapClient>(node_);
  map_->on_delta([this](const map::MapDelta& d) { planner_.on_map_changes(d.changes); });
  map_->on_reset([this] { planner_.on_map_reset(); });
  node_.subscribe<semx::odometry_t>(
      semx::channels::ODOMETRY, [this](const semx::odometry_t& m) { planner_.set_pose(to_pose(m)); },
      accept_odometry);
  node_.subscribe<semx::semantic_regions_t>(
      semx::channels::SEMANTIC_REGIONS,
      [this](const semx::semantic_regions_t& m) { planner_.set_regions(to_regions(m)); }, accept_regions);
  node_.subscribe<semx::controller_status_t>(
      semx::channels::CONTROLLER_STATUS,
      [this](const semx::controller_status_t& m) {
        planner_.on_controller_status(static_cast<ControllerState>(m.state), m.plan_id, m.utime);
      },
      accept_controller_status);
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  node_.on_quiet_until([this](int64_t utime) {
    // A mirror out of sync may request a snapshot on any tick.
    if (!map_->in_sync() || last_status_utime_ < 0) return utime;
    // A cycle run after this ack releases nothing before its least charge.
    const int64_t next =
        deferred_cycle_utime_ == utime ? utime + planner_.min_charge_us() : planner_.quiet_until(utime);
    return std::min(next, last_status_utime_ + kStatusPeriodUs);
  });
  node_.set_state(runtime::NodeState::kRunning,
                  std::string(to_string(planner_.kind())) + ": waiting for the map");
}

void PlannerNode::set_truth(std::shared_ptr<const TruthMap> truth) {
  truth_ = std::move(truth);
  planner_.set_truth(truth_.get());
}

void PlannerNode::on_tick(int64_t /*tick*/, int64_t utime) {
  if (last_utime_ >= 0 && utime < last_utime_) {
    // The clock restarted (a new episode): nothing from the old one applies.
    planner_.reset();
    last_status_utime_ = -1;
  }
  last_utime_ = utime;
  // A mirror waiting for a snapshot is not the mapper's map: no planning on it (the planner
  // starts over from the map it gets back, as after any reset).
  planner_.set_map(map_->in_sync() ? &map_->mirror().grid() : nullptr);
  // With a least charge the cycle's outputs go out on a later tick, so it runs after this tick's
  // ack and the clock goes on meanwhile (in LOCKSTEP; at once otherwise).
  bool due = false;
  ExplorationPlanner::Output out =
      planner_.min_charge_us() > 0 ? planner_.poll(utime, due) : planner_.tick(utime);
  if (due) {
    deferred_cycle_utime_ = utime;
    node_.after_ack([this, utime] {
      planner_.run_due_cycle(utime);
      deferred_cycle_utime_ = -1;
      if (planner_.state() != reported_state_) update_node_state();
    });
  }
  if (out.path) node_.publish(semx::channels::PLAN_PATH, to_message(*out.path, utime));
  if (out.roadmap) node_.publish(semx::channels::ROADMAP, to_message(*out.roadmap, utime));
  if (out.status) {
    node_.publish(semx::channels::PLANNER_STATUS, to_message(*out.status, utime));
    last_status_utime_ = utime;
  } else if (last_status_utime_ >= 0 && utime - last_status_utime_ >= kStatusPeriodUs) {
    node_.publish(semx::channels::PLANNER_STATUS, to_message(planner_.last_status(), utime));
    last_status_utime_ = utime;
  }
  if (planner_.state() != reported_state_ || out.status) update_node_state();
}

void PlannerNode::update_node_state() {
  reported_state_ = planner_.state();
  // The oracle's plan, once made: what it promises to see, for the run's log (logs/planner.log).
  if (const auto* o = dynamic_cast<const OracleStrategy*>(&planner_.strategy()); o && !oracle_reported_) {
    if (o->summary().ready || !o->summary().error.empty()) {
      std::cout << "semx-planner: " << o->summary().describe() << std::endl;
      oracle_reported_ = true;
    }
  }
  const StatusReport& s = planner_.last_status();
  std::string detail = std::string(to_string(planner_.kind())) + " " + to_string(planner_.state()) + " it " +
                       std::to_string(planner_.iteration()) + ", plan " + std::to_string(planner_.plan_id()) +
                       ", " + std::to_string(s.num_nodes) + " nodes";
  if (planner_.state() == PlannerState::kDone) detail += ": " + s.reason;
  node_.set_state(
      planner_.state() == PlannerState::kDone ? runtime::NodeState::kDone : runtime::NodeState::kRunning,
      detail);
}

}  // namespace semx::planner
