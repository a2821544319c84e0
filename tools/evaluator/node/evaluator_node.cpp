#include "evaluator_node.hpp"

#include <semx/node_status_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>
#include <semx/sim_event_t.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <unordered_map>

#include "semx/core/angles.hpp"
#include "semx/evaluator/map_picture.hpp"
#include "semx/evaluator/run_folder.hpp"
#include "semx/evaluator/time_split_picture.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/monotonic_clock.hpp"

namespace semx::evaluator {

namespace ch = semx::channels;

namespace {

double epoch_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

constexpr uint32_t kStateKind = runtime::state_kind("EVAL");

map::MapClientOptions client_options(const runtime::Node& node) {
  map::MapClientOptions o;
  o.resolution = 0;  // adopt the mapper's; the ground truth follows it
  o.requester = node.name();
  return o;
}

bool finite3(const double* v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

EvaluatorNode::EvaluatorNode(runtime::Node& node, simulator::World world, EvaluatorNodeOptions options)
    : node_(node),
      options_(std::move(options)),
      evaluation_(std::move(world), options_.evaluation),
      map_(node_, client_options(node_)) {
  map_.on_delta([this](const map::MapDelta& d) {
    note_wall();
    evaluation_.on_map_delta(d, map_.mirror().grid());
    message_time(d.utime);
  });
  map_.on_reset([this] {
    const int64_t t = std::max(node_.now_utime(), evaluation_.metrics().now_utime());
    evaluation_.on_map_reset(map_.mirror().grid(), t, map_.seq());
  });
  node_.subscribe<semx::odometry_t>(
      ch::ODOMETRY,
      [this](const semx::odometry_t& m) {
        note_wall();
        message_time(m.utime);
        evaluation_.on_odometry(
            m.utime, Eigen::Vector3d(m.position[0], m.position[1], m.position[2]),
            core::yaw_of_quaternion(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]));
      },
      [](const semx::odometry_t& m) { return finite3(m.position); });
  node_.subscribe<semx::sim_event_t>(ch::SIM_EVENT, [this](const semx::sim_event_t& m) {
    if (m.type == semx::sim_event_t::EPISODE_END) {
      // Everything of the last tick is in: apply what the map client still holds, then end.
      map_.on_tick(node_.clock().last_tick() + 1, std::numeric_limits<int64_t>::max());
      finish_at(Termination::kEpisodeEnd, m.utime);
      return;
    }
    message_time(m.utime);
    if (m.type == semx::sim_event_t::COLLISION) {
      evaluation_.on_collision(m.utime, m.count);
      if (options_.print) {
        std::printf("semx-evaluator: COLLISION at t=%.2f s (%.2f, %.2f, %.2f), solid %d\n", m.utime * 1e-6,
                    m.position[0], m.position[1], m.position[2], m.solid_index);
        std::fflush(stdout);
      }
    }
  });
  node_.subscribe<semx::planner_status_t>(ch::PLANNER_STATUS, [this](const semx::planner_status_t& m) {
    message_time(m.utime);
    const PlannerState before = evaluation_.planner_state();
    evaluation_.on_planner_status(m.utime, m.planner, planner_state_from_int(m.state), m.reason);
    if (options_.print && before != PlannerState::kDone &&
        evaluation_.planner_state() == PlannerState::kDone) {
      std::printf("semx-evaluator: planner DONE at t=%.2f s%s%s\n", m.utime * 1e-6,
                  m.reason.empty() ? "" : ": ", m.reason.c_str());
      std::fflush(stdout);
    }
  });
  // Only kept for the run folder's picture: the last of each, nothing is computed from them.
  node_.subscribe<semx::roadmap_t>(ch::ROADMAP, [this](const semx::roadmap_t& m) {
    RoadmapOverlay r;
    std::unordered_map<int64_t, Eigen::Vector2d> at;
    for (const auto& n : m.nodes) {
      if (!finite3(n.position)) continue;
      const Eigen::Vector2d p(n.position[0], n.position[1]);
      at.emplace(n.id, p);
      r.nodes.push_back(p);
      r.frontier.push_back((n.flags & semx::roadmap_node_t::FRONTIER) != 0);
      r.gain.push_back(n.gain);
    }
    const size_t edges = std::min(m.edge_from.size(), m.edge_to.size());
    for (size_t i = 0; i < edges; ++i) {
      const auto a = at.find(m.edge_from[i]), b = at.find(m.edge_to[i]);
      if (a != at.end() && b != at.end()) r.edges.emplace_back(a->second, b->second);
    }
    roadmap_ = std::move(r);
  });
  node_.subscribe<semx::semantic_regions_t>(ch::SEMANTIC_REGIONS, [this](const semx::semantic_regions_t& m) {
    std::vector<RegionOverlay> regions;
    for (const auto& g : m.regions) {
      if (!finite3(g.centroid) || !std::isfinite(g.radius) || g.radius < 0 || g.radius > 100) continue;
      regions.push_back({Eigen::Vector2d(g.centroid[0], g.centroid[1]), g.radius, g.label, g.active != 0});
    }
    regions_ = std::move(regions);
  });
  // Who of the set restarted, and when (a disturbed run is marked so in metrics.json), and each
  // node's messages lost for good.
  node_.subscribe<semx::node_status_t>(ch::NODE_STATUS, [this](const semx::node_status_t& m) {
    // A recorder's or viewer's losses leave its log or picture short, not the run.
    if (m.lost > 0 && !m.observer) lost_[m.node] = std::max(lost_[m.node], m.lost);
    // Nor does an observer that comes and goes (a viewer opened twice, another pid under one
    // name): only one the launcher brought back (its restart count rises: the set's logger, whose
    // log now has a hole) is recorded.
    if (m.observer && m.restarts <= 0) return;
    const int64_t t = std::max(node_.now_utime(), evaluation_.metrics().now_utime());
    const size_t before = evaluation_.restarts().size();
    evaluation_.on_node_status(m.node, m.pid, m.restarts, t);
    if (options_.print && evaluation_.restarts().size() > before) {
      const NodeRestart& r = evaluation_.restarts().back();
      std::printf("semx-evaluator: %s restarted (restart %d) at t=%.2f s: the run is marked disturbed\n",
                  r.node.c_str(), r.restarts, r.t_s);
      std::fflush(stdout);
    }
  });
  node_.on_tick([this](int64_t tick, int64_t utime) { on_tick(tick, utime); });
  // It publishes nothing but its map client's requests: with the mirror in sync the clock need
  // not wait for it (it ends the set from message time, wherever the clock is by then).
  node_.on_quiet_until(
      [this](int64_t utime) { return map_.in_sync() ? std::numeric_limits<int64_t>::max() : utime; });
  open_state();
  node_.set_state(runtime::NodeState::kRunning, "waiting for the simulation");
}

void EvaluatorNode::open_state() {
  if (options_.state_path.empty()) return;
  uint64_t valid = 0;
  if (options_.resume) {
    const auto records = runtime::read_state_journal(options_.state_path, kStateKind, &valid);
    for (size_t i = 0; i < records.size(); ++i) {
      const auto& rec = records[i];
      core::ByteReader r(rec.data(), rec.size());
      try {
        const double epoch = r.f64();
        next_progress_s_ = r.f64();
        evaluation_.restore(r);
        if (epoch > 0) wall_start_epoch_ = epoch;
      } catch (const std::exception& e) {
        throw runtime::StateFileError(options_.state_path + ": record " + std::to_string(i + 1) + ": " +
                                      e.what());
      }
    }
    restored_records_ = records.size();
    if (wall_start_epoch_ > 0) wall_start_ = semx::runtime::monotonic_s() - (epoch_now() - wall_start_epoch_);
    saved_samples_ = evaluation_.metrics().samples().size();
  }
  journal_ = std::make_unique<runtime::StateJournal>(options_.state_path, kStateKind, !options_.resume);
  // A record cut short by the crash is dropped; the next one follows the last whole one.
  if (options_.resume) journal_->truncate(valid);
  saved_ = evaluation_.metrics().sizes();
  if (options_.resume) {
    // This evaluator is itself a restart: the run is disturbed even if it never hears its own
    // status.
    const auto self = node_.status();
    evaluation_.on_node_status(self.node, self.pid, self.restarts, evaluation_.metrics().now_utime());
  }
}

void EvaluatorNode::save_state() {
  if (!journal_) return;
  std::vector<uint8_t> bytes;
  core::ByteWriter w(bytes);
  w.f64(wall_start_epoch_);
  w.f64(next_progress_s_);
  evaluation_.save(w, saved_);
  try {
    journal_->append(bytes);
  } catch (const runtime::StateFileError& e) {
    std::cerr << "semx-evaluator: " << e.what() << " (the run goes on without saving its state)\n";
    journal_.reset();
  }
}

void EvaluatorNode::note_wall() {
  if (wall_start_ < 0) {
    wall_start_ = semx::runtime::monotonic_s();
    wall_start_epoch_ = epoch_now();
  }
}

double EvaluatorNode::wall_s() const {
  if (wall_start_ < 0) return 0.0;
  return (wall_end_ >= 0 ? wall_end_ : semx::runtime::monotonic_s()) - wall_start_;
}

void EvaluatorNode::on_tick(int64_t /*tick*/, int64_t utime) {
  note_wall();
  end_if_due(utime);
  if (finished()) return;
  evaluation_.advance(utime);
  progress(utime);
  // A record per coverage sample: what a crash loses is at most one sample period.
  if (evaluation_.metrics().samples().size() != saved_samples_) {
    saved_samples_ = evaluation_.metrics().samples().size();
    save_state();
  }
}

void EvaluatorNode::message_time(int64_t utime) {
  if (node_.clock().started() || finished()) return;
  end_if_due(utime);
  if (finished()) return;
  evaluation_.advance(utime);
  progress(utime);
}

void EvaluatorNode::end_if_due(int64_t utime) {
  if (const auto why = evaluation_.due(utime)) finish_at(*why, utime);
}

void EvaluatorNode::progress(int64_t utime) {
  if (!(options_.progress_s > 0)) return;
  const double t = static_cast<double>(utime) * 1e-6;
  if (t < next_progress_s_) return;
  next_progress_s_ = (std::floor(t / options_.progress_s) + 1) * options_.progress_s;
  const auto& m = evaluation_.metrics();
  const std::string line = format_progress(t, m.coverage_pct(), m.object_coverage_pct(), m.distance_m(),
                                           to_string(m.planner_state()));
  if (options_.print) {
    std::printf("semx-evaluator: %s\n", line.c_str());
    std::fflush(stdout);
  }
  node_.set_state(runtime::NodeState::kRunning, line);
}

void EvaluatorNode::check_validity() {
  if (node_.counters().lost > 0) lost_[node_.name()] = node_.counters().lost;
  std::string lost;
  int64_t total = 0;
  for (const auto& [name, n] : lost_) {
    lost += (lost.empty() ? "" : ", ") + name + " " + std::to_string(n);
    total += n;
  }
  if (total > 0) evaluation_.mark_invalid(std::to_string(total) + " messages lost for good (" + lost + ")");
  const int64_t gaps = map_.has_mirror() ? map_.mirror().counters().gaps : 0;
  if (gaps > 0) {
    evaluation_.mark_invalid(std::to_string(gaps) +
                             " gaps in the MAP_UPDATE sequence (the map was resynchronised from snapshots)");
  }
}

void EvaluatorNode::finish_at(Termination why, int64_t utime) {
  if (finished()) return;
  wall_end_ = semx::runtime::monotonic_s();
  check_validity();
  evaluation_.finish(why, utime, wall_s());
  write_folder();
  const RunSummary s = evaluation_.summary();
  if (options_.print) {
    std::printf("semx-evaluator: run ended (%s) at t=%.2f s\n%s", s.termination.c_str(), s.sim_s,
                format_metrics_table(s).c_str());
    if (!written_.empty()) {
      std::printf("semx-evaluator: run folder %s\n", options_.out_dir.c_str());
    }
    if (!s.valid) {
      std::printf(
          "\033[31msemx-evaluator: this run is NOT VALID: %s. Its figures are not the ones the seed "
          "gives; the bench leaves it out of its tables.\033[0m\n",
          s.invalid_reason.c_str());
    }
    std::fflush(stdout);
  }
  char detail[160];
  std::snprintf(detail, sizeof detail, "%s: coverage %.1f%%, Time_f %.1f s", s.termination.c_str(),
                s.coverage_pct, s.time_f_s);
  node_.set_state(write_failed_ ? runtime::NodeState::kFailed : runtime::NodeState::kDone, detail);
  node_.stop();
}

bool EvaluatorNode::finish(Termination why) {
  finish_at(why, std::max(node_.now_utime(), evaluation_.metrics().now_utime()));
  return !write_failed_;
}

void EvaluatorNode::write_folder() {
  if (options_.out_dir.empty()) return;
  try {
    const RunSummary s = evaluation_.summary();
    written_ = write_run_metrics(options_.out_dir, s);
    const map::StateGrid empty(evaluation_.tracker().resolution());
    const map::StateGrid& grid = map_.has_mirror() ? map_.mirror().grid() : empty;
    const std::string title = (s.info.world.empty() ? std::string("map") : s.info.world) +
                              (s.info.planner.empty() ? "" : ", " + s.info.planner) + "  coverage " +
                              std::to_string(static_cast<int>(std::floor(s.coverage_pct))) +
                              " %, t=" + std::to_string(static_cast<int>(std::lround(s.time_f_s))) + " s";
    const std::string png = (std::filesystem::path(options_.out_dir) / "map.png").string();
    // The roadmap and the regions beneath the trajectory, so the flight stays readable.
    run_map_picture(grid, evaluation_.world(), &evaluation_.ground_truth(), s.trajectory, title,
                    [this](MapPicture& p) {
                      add_roadmap(p, roadmap_);
                      add_regions(p, regions_);
                    })
        .write_png(png);
    written_.push_back(png);
    const std::string split_png = (std::filesystem::path(options_.out_dir) / "time_split.png").string();
    time_split_picture(grid, evaluation_.world(), &evaluation_.ground_truth(), s.time_split,
                       "where the time went: " + title)
        .write_png(split_png);
    written_.push_back(split_png);
    const std::string bt = (std::filesystem::path(options_.out_dir) / "map.bt").string();
    write_octomap_bt(grid, bt);
    written_.push_back(bt);
  } catch (const std::exception& e) {
    write_failed_ = true;
    std::cerr << "semx-evaluator: " << e.what() << "\n";
  }
}

int EvaluatorNode::run() {
  while (!finished() && !node_.stopped()) {
    if (node_.spin_once(100) < 0) {
      std::cerr << "semx-evaluator: the LCM provider failed\n";
      break;
    }
  }
  if (!finished()) finish(Termination::kStopped);
  return write_failed_ ? 1 : 0;
}

}  // namespace semx::evaluator
