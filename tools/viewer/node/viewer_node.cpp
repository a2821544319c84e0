#include "viewer_node.hpp"

#include <semx/map_snapshot_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/trajectory_t.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "semx/runtime/channels.hpp"
#include "semx/runtime/roadmap_messages.hpp"

namespace semx::viewer {

namespace ch = semx::channels;

namespace {

map::MapClientOptions client_options(const runtime::Node& node) {
  map::MapClientOptions o;
  o.resolution = 0;  // adopt the mapper's
  o.requester = node.name();
  o.quiet = true;
  return o;
}

Eigen::Vector3d vec3(const double* v) { return {v[0], v[1], v[2]}; }

}  // namespace

ViewerNode::ViewerNode(runtime::Node& node, ViewerNodeOptions options)
    : node_(node), options_(std::move(options)), view_(options_.view), schedule_(options_.period_s) {
  if (options_.world) view_.set_world(*options_.world);
  if (!options_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options_.out_dir, ec);
    if (ec || !std::filesystem::is_directory(options_.out_dir)) {
      throw std::runtime_error("cannot create the frame folder '" + options_.out_dir + "'" +
                               (ec ? ": " + ec.message() : ""));
    }
  }
  // Before the MapClient subscribes: the Node delivers a channel's subscriptions in order, so a
  // frame a map message makes due is drawn before the MapClient applies that message.
  node_.subscribe<semx::map_update_t>(ch::MAP_UPDATE,
                                      [this](const semx::map_update_t& m) { message_time(m.utime); });
  node_.subscribe<semx::map_snapshot_t>(ch::MAP_SNAPSHOT,
                                        [this](const semx::map_snapshot_t& m) { message_time(m.utime); });
  map_ = std::make_unique<map::MapClient>(node_, client_options(node_));

  node_.subscribe<semx::odometry_t>(ch::ODOMETRY, [this](const semx::odometry_t& m) {
    message_time(m.utime);
    view_.add_pose(m.utime, vec3(m.position),
                   Eigen::Vector4d(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]));
  });
  node_.subscribe<semx::roadmap_t>(ch::ROADMAP, [this](const semx::roadmap_t& m) {
    message_time(m.utime);
    view_.set_roadmap(runtime::roadmap_from(m));
  });
  node_.subscribe<semx::semantic_regions_t>(ch::SEMANTIC_REGIONS, [this](const semx::semantic_regions_t& m) {
    message_time(m.utime);
    view_.set_regions(runtime::regions_from(m));
  });
  node_.subscribe<semx::path_t>(ch::PLAN_PATH, [this](const semx::path_t& m) {
    message_time(m.utime);
    std::vector<Eigen::Vector3d> w;
    w.reserve(m.waypoints.size());
    for (const auto& p : m.waypoints) w.emplace_back(p[0], p[1], p[2]);
    view_.set_path(std::move(w));
  });
  node_.subscribe<semx::trajectory_t>(ch::TRAJECTORY, [this](const semx::trajectory_t& m) {
    message_time(m.utime);
    TrajectoryCurve c;
    c.degree = m.degree;
    c.knot_interval = m.knot_interval;
    c.optimized = m.optimized;
    c.control_points.reserve(m.control_points.size());
    for (const auto& p : m.control_points) c.control_points.emplace_back(p[0], p[1], p[2]);
    view_.set_trajectory(c);
  });
  node_.subscribe<semx::planner_status_t>(ch::PLANNER_STATUS, [this](const semx::planner_status_t& m) {
    message_time(m.utime);
    view_.set_planner({m.planner, m.state, m.reason, m.iteration});
  });
  // After the MapClient's tick handler, so a tick's frame shows the map messages it applied.
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  node_.set_state(runtime::NodeState::kRunning, "waiting for messages");
}

void ViewerNode::message_time(int64_t utime) {
  if (node_.clock().started()) return;  // the ticks keep the time
  if (utime < 0) return;
  if (time_ >= 0 && static_cast<double>(utime - time_) > options_.max_time_jump_s * 1e6) return;
  maybe_draw(utime);
  time_ = std::max(time_, utime);
  view_.set_time(time_);
}

void ViewerNode::on_tick(int64_t tick, int64_t utime) {
  if (tick == 0 && last_tick_ > 0) {
    // A new episode: its frames restart at 0 and the old trail goes.
    schedule_.reset();
    view_.clear_run();
    time_ = -1;
  }
  last_tick_ = tick;
  time_ = utime;
  view_.set_time(utime);
  maybe_draw(utime);
}

void ViewerNode::maybe_draw(int64_t utime) {
  const int64_t k = schedule_.due(utime);
  if (k >= 0) draw_frame(k);
}

void ViewerNode::draw_frame(int64_t index) {
  const map::StateGrid* grid = map_->has_mirror() ? &map_->mirror().grid() : nullptr;
  const evaluator::Image img = view_.render(grid);
  ++frames_;
  if (!options_.out_dir.empty()) {
    const std::string file =
        (std::filesystem::path(options_.out_dir) / (index >= 0 ? frame_file_name(index) : "final.png"))
            .string();
    try {
      evaluator::write_png(img, file);
      last_file_ = file;
      degraded_ = false;
    } catch (const std::exception& e) {
      // The first failure and then every 100th: a full disk must not flood the terminal.
      if (write_errors_++ % 100 == 0) std::cerr << node_.name() << ": " << e.what() << "\n";
      degraded_ = true;
      node_.set_state(runtime::NodeState::kDegraded, std::string("cannot write frames: ") + e.what());
    }
  }
  if (options_.on_frame) options_.on_frame(img, index);
  char b[160];
  std::snprintf(b, sizeof b, "frame %lld at t=%.1f s, map seq %lld", static_cast<long long>(index),
                static_cast<double>(view_.time_utime()) * 1e-6, static_cast<long long>(map_->seq()));
  if (!degraded_) node_.set_state(runtime::NodeState::kRunning, b);
  if (options_.print && index >= 0 && index % 10 == 0) {
    std::printf("semx-viewer: %s%s\n", b, last_file_.empty() ? "" : (" -> " + last_file_).c_str());
    std::fflush(stdout);
  }
}

int ViewerNode::run(const std::function<bool()>& idle) {
  const bool from_file = node_.url().rfind("file://", 0) == 0;
  int rc = 0;
  while (!node_.stopped()) {
    const int r = node_.spin_once(idle ? 20 : 100);
    if (r < 0) {
      if (from_file) break;  // the end of the log
      node_.set_state(runtime::NodeState::kFailed, "LCM provider failed");
      rc = 1;
      break;
    }
    if (idle && !idle()) break;
  }
  draw_frame(-1);
  if (options_.print && !last_file_.empty()) {
    std::printf("semx-viewer: %lld frames; last state in %s\n", static_cast<long long>(frames_),
                last_file_.c_str());
    std::fflush(stdout);
  }
  if (rc == 0) node_.set_state(runtime::NodeState::kStopping, from_file ? "end of log" : "stopped");
  return rc;
}

}  // namespace semx::viewer
