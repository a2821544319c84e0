#include "log_eval.hpp"

#include <lcm/lcm-cpp.hpp>
#include <semx/clock_t.hpp>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/sim_event_t.hpp>

#include <cmath>
#include <filesystem>
#include <limits>

#include "map_messages.hpp"
#include "semx/evaluator/map_picture.hpp"
#include "semx/evaluator/run_folder.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_schema.hpp"
#include "semx/runtime/wire_validator.hpp"

namespace semx::evaluator {

namespace ch = semx::channels;
namespace fs = std::filesystem;

struct LogEvaluator::Held {
  bool snapshot = false;
  int64_t utime = 0;
  map::MapDelta delta;
  map::MapSnapshot snap;
};

namespace {

// Validates and decodes one event as T, as a live subscription would. False with `why` set when
// the bytes are not a usable T.
template <class T>
bool decode_event(const lcm::LogEvent& e, std::size_t size, T& out, std::string& why) {
  const auto& schema = runtime::LcmSchema::semx();
  const runtime::LcmStruct* type = schema.find(std::string("semx.") + T::getTypeName());
  if (!type) {
    why = std::string("no .lcm layout for ") + T::getTypeName();
    return false;
  }
  const auto* data = static_cast<const uint8_t*>(e.data);
  const runtime::WireError we = runtime::validate_wire(schema, *type, T::getHash(), data, size);
  if (we != runtime::WireError::kNone) {
    why = runtime::to_string(we);
    return false;
  }
  try {
    if (out.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) {
      why = "decoder rejected it";
      return false;
    }
  } catch (const std::exception& ex) {
    why = std::string("decoder threw: ") + ex.what();
    return false;
  }
  return true;
}

bool finite3(const double* v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

bool same_resolution(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(a, b); }

std::string resolve_world(const std::string& w) {
  return w.find('/') == std::string::npos && w.find(".yaml") == std::string::npos
             ? simulator::shipped_world_path(w)
             : w;
}

std::string world_stem(const std::string& path) { return fs::path(path).stem().string(); }

}  // namespace

std::string world_named_in_log(const std::string& log_path, const runtime::LogLayout& layout,
                               runtime::LogSession& session) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) return "";
  std::string why;
  for (int64_t i = 0; i < layout.events; ++i) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    if (e->channel != ch::SIM_EVENT) continue;
    // By session only, not through session.payload(): its replay window is for the real pass.
    const auto* data = static_cast<const uint8_t*>(e->data);
    const auto size = static_cast<std::size_t>(e->datalen);
    const auto trailer = runtime::read_trailer(data, size);
    if (session.signed_log() && (!trailer || trailer->session != session.session())) continue;
    const std::size_t payload = trailer ? size - runtime::kAuthTrailerBytes : size;
    semx::sim_event_t ev{};
    if (decode_event(*e, payload, ev, why) && ev.type == semx::sim_event_t::EPISODE_START) return ev.description;
  }
  return "";
}

LogEvaluator::LogEvaluator(LogEvalOptions options) : options_(std::move(options)) {
  try {
    report_.layout = runtime::scan_log(options_.log_path);
  } catch (const runtime::LogError& e) {
    throw LogEvalError(e.what());
  }
  std::optional<runtime::AuthKey> key;
  try {
    key = options_.auth_key_file.empty() ? runtime::key_beside(options_.log_path)
                                         : runtime::AuthKey::from_file(options_.auth_key_file);
    session_ = std::make_unique<runtime::LogSession>(options_.log_path, report_.layout, key);
  } catch (const std::exception& e) {
    throw LogEvalError(e.what());
  }
  report_.verified = session_->verified();
  std::string world = options_.world;
  const std::string logged = world_named_in_log(options_.log_path, report_.layout, *session_);
  if (world.empty()) {
    world = logged;
    if (world.empty()) {
      throw LogEvalError(options_.log_path +
                         ": the log names no world (no SIM_EVENT EPISODE_START); give it with --world");
    }
  }
  world_path_ = resolve_world(world);
  simulator::World w = simulator::load_world(world_path_);
  if (!logged.empty() && !w.name.empty() && w.name != logged && !options_.any_world) {
    throw LogEvalError(options_.log_path + ": the log's world is '" + logged + "' (SIM_EVENT EPISODE_START), not '" +
                       w.name + "' (" + world_path_ + "); give --world " + logged +
                       " or --any-world to evaluate against this one anyway");
  }
  EvaluationOptions eo = options_.evaluation;
  if (eo.info.world.empty()) eo.info.world = w.name.empty() ? world_stem(world_path_) : w.name;
  if (eo.info.world_path.empty()) eo.info.world_path = world_path_;
  eo.info.source = "log";
  evaluation_ = std::make_unique<Evaluation>(std::move(w), std::move(eo));
  empty_ = std::make_unique<map::StateGrid>(evaluation_->tracker().resolution());
}

LogEvaluator::~LogEvaluator() = default;
LogEvaluator::LogEvaluator(LogEvaluator&&) noexcept = default;
LogEvaluator& LogEvaluator::operator=(LogEvaluator&&) noexcept = default;

const map::StateGrid& LogEvaluator::grid() const { return mirror_ ? mirror_->grid() : *empty_; }

void LogEvaluator::apply(const Held& h) {
  if (evaluation_->finished()) return;
  if (h.snapshot) {
    if (mirror_ && !same_resolution(h.snap.resolution, mirror_->resolution())) mirror_.reset();
    if (!mirror_) mirror_ = std::make_unique<map::MapMirror>(h.snap.resolution);
    if (mirror_->apply(h.snap) == map::MapMirror::SnapshotResult::kApplied) {
      evaluation_->on_map_reset(mirror_->grid(), h.utime, mirror_->seq());
    }
    return;
  }
  if (!mirror_) mirror_ = std::make_unique<map::MapMirror>(h.delta.resolution);
  const int64_t gaps = mirror_->counters().gaps;
  if (mirror_->apply(h.delta) == map::MapMirror::DeltaResult::kApplied) {
    evaluation_->on_map_delta(h.delta, mirror_->grid());
  }
  report_.map_gaps += mirror_->counters().gaps - gaps;
}

void LogEvaluator::flush(int64_t before_utime) {
  std::vector<Held> later;
  for (Held& h : held_) {
    if (h.utime < before_utime) {
      apply(h);
    } else {
      later.push_back(std::move(h));
    }
  }
  held_.swap(later);
}

void LogEvaluator::observe(int64_t utime) {
  if (report_.clock || evaluation_->finished()) return;
  if (const auto why = evaluation_->due(utime)) {
    evaluation_->finish(*why, utime, report_.log_wall_s);
  } else {
    evaluation_->advance(utime);
  }
}

void LogEvaluator::run() {
  if (ran_) return;
  ran_ = true;
  Evaluation& ev = *evaluation_;
  lcm::LogFile log(options_.log_path, "r");
  if (!log.good()) throw LogEvalError(options_.log_path + ": lcm::LogFile cannot open it");
  int64_t first_ts = -1;
  auto bad = [&](int64_t i, const std::string& channel, const std::string& why) {
    ++report_.malformed;
    if (report_.first_error.empty()) {
      report_.first_error = "event " + std::to_string(i) + " (" + channel + "): " + why;
    }
  };
  // Messages are decoded into fresh objects: LCM's generated decoder leaves a variable-length
  // array untouched when its length is 0, so a reused object would keep the previous content.
  std::string why;
  // Only the events the scan found complete: LogFile's reader is not safe past them.
  for (int64_t i = 0; i < report_.layout.events && !ev.finished(); ++i) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) throw LogEvalError(options_.log_path + ": lcm::LogFile stopped at event " + std::to_string(i));
    why.clear();
    const auto payload =
        session_->payload(e->channel, static_cast<const uint8_t*>(e->data), static_cast<std::size_t>(e->datalen));
    if (!payload) continue;
    const std::size_t n = *payload;
    ++report_.events_read;
    ++report_.channels[e->channel];
    const std::string& c = e->channel;
    // The run's wall time, as the live evaluator counts it: from the first SIM_CLOCK, ODOMETRY or
    // MAP_UPDATE (the simulation running, not the logger or the mapper starting) to the event
    // that ended the run.
    if (first_ts < 0 && (c == ch::SIM_CLOCK || c == ch::ODOMETRY || c == ch::MAP_UPDATE))
      first_ts = e->timestamp;
    if (first_ts >= 0) {
      report_.log_wall_s = std::max(report_.log_wall_s, static_cast<double>(e->timestamp - first_ts) * 1e-6);
    }
    if (c == ch::SIM_CLOCK) {
      semx::clock_t clock{};
      if (!decode_event(*e, n, clock, why)) {
        bad(i, c, why);
        continue;
      }
      report_.clock = true;
      flush(clock.utime);
      if (const auto end = ev.due(clock.utime)) {
        ev.finish(*end, clock.utime, report_.log_wall_s);
      } else {
        ev.advance(clock.utime);
      }
    } else if (c == ch::MAP_UPDATE) {
      Held h;
      semx::map_update_t update{};
      if (!decode_event(*e, n, update, why) || !map::accept_update(update) ||
          !map::from_message(update, h.delta)) {
        bad(i, c, why.empty() ? "content rejected" : why);
        continue;
      }
      h.utime = update.utime;
      if (report_.clock) {
        held_.push_back(std::move(h));
      } else {
        apply(h);
        observe(h.utime);
      }
    } else if (c == ch::MAP_SNAPSHOT) {
      Held h;
      semx::map_snapshot_t snapshot{};
      if (!decode_event(*e, n, snapshot, why) || !map::accept_snapshot(snapshot)) {
        bad(i, c, why.empty() ? "content rejected" : why);
        continue;
      }
      h.snapshot = true;
      h.utime = snapshot.utime;
      h.snap = map::from_message(snapshot);
      if (report_.clock) {
        held_.push_back(std::move(h));
      } else {
        apply(h);
        observe(h.utime);
      }
    } else if (c == ch::ODOMETRY) {
      semx::odometry_t odometry{};
      if (!decode_event(*e, n, odometry, why) || !finite3(odometry.position)) {
        bad(i, c, why.empty() ? "position not finite" : why);
        continue;
      }
      observe(odometry.utime);
      ev.on_odometry(odometry.utime,
                     Eigen::Vector3d(odometry.position[0], odometry.position[1], odometry.position[2]));
    } else if (c == ch::SIM_EVENT) {
      semx::sim_event_t event{};
      if (!decode_event(*e, n, event, why)) {
        bad(i, c, why);
        continue;
      }
      if (event.type == semx::sim_event_t::EPISODE_END) {
        flush(std::numeric_limits<int64_t>::max());
        ev.on_episode_end(event.utime, report_.log_wall_s);
        continue;
      }
      observe(event.utime);
      if (event.type == semx::sim_event_t::COLLISION) ev.on_collision(event.utime, event.count);
    } else if (c == ch::PLANNER_STATUS) {
      semx::planner_status_t status{};
      if (!decode_event(*e, n, status, why)) {
        bad(i, c, why);
        continue;
      }
      observe(status.utime);
      ev.on_planner_status(status.utime, status.planner, planner_state_from_int(status.state), status.reason);
    }
  }
  report_.left_out = session_->summary();
  flush(std::numeric_limits<int64_t>::max());
  if (!ev.finished()) ev.finish(Termination::kLogEnd, ev.metrics().now_utime(), report_.log_wall_s);
}

std::vector<std::string> LogEvaluator::write_folder(const std::string& dir) const {
  const RunSummary s = evaluation_->summary();
  std::vector<std::string> written = write_run_metrics(dir, s);
  const std::string title = (s.info.world.empty() ? std::string("map") : s.info.world) +
                            (s.info.planner.empty() ? "" : ", " + s.info.planner) + " (from the log)";
  const std::string png = (fs::path(dir) / "map.png").string();
  run_map_picture(grid(), evaluation_->world(), &evaluation_->ground_truth(), s.trajectory, title)
      .write_png(png);
  written.push_back(png);
  return written;
}

}  // namespace semx::evaluator
