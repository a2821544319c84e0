#include "controller_replay.hpp"

#include <lcm/lcm-cpp.hpp>
#include <semx/esdf_local_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/path_t.hpp>

#include <memory>
#include <optional>

#include "controller_messages.hpp"
#include "semx/controller/path.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/log_session.hpp"

namespace semx::controller {
namespace {

// The message, or nothing when the bytes are not a whole one.
template <class Msg>
std::optional<Msg> decode(const uint8_t* data, std::size_t size) {
  Msg m;
  try {
    if (m.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return m;
}

}  // namespace

PathReplay replay_paths(const std::string& log_path, const ControllerConfig& config, double from, double to) {
  PathReplay r;
  runtime::LogLayout layout;
  std::unique_ptr<runtime::LogSession> session;
  try {
    layout = runtime::scan_log(log_path);
    session = std::make_unique<runtime::LogSession>(log_path, layout, runtime::key_beside(log_path));
  } catch (const std::exception& e) {
    throw ReplayError(e.what());
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw ReplayError(log_path + ": lcm::LogFile cannot open it");

  const TrajectoryGenerator generator(config);
  const OutsideWindow outside =
      config.clearance.outside_is_obstacle ? OutsideWindow::kObstacle : OutsideWindow::kFree;
  std::shared_ptr<const GridDistanceField> field;
  std::optional<VehicleState> vehicle;
  // Only the events the scan found complete: LogFile's reader is not safe past them.
  for (int64_t i = 0; i < layout.events; ++i) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) throw ReplayError(log_path + ": lcm::LogFile stopped at event " + std::to_string(i));
    const auto* data = static_cast<const uint8_t*>(e->data);
    const auto size = session->payload(e->channel, data, static_cast<std::size_t>(e->datalen));
    if (!size) continue;
    if (e->channel == semx::channels::ESDF_LOCAL) {
      const auto m = decode<semx::esdf_local_t>(data, *size);
      if (!m || !accept_esdf(*m)) {
        ++r.malformed;
        continue;
      }
      ++r.esdf_events;
      field = std::make_shared<const GridDistanceField>(to_distance_field(*m, outside));
    } else if (e->channel == semx::channels::ODOMETRY) {
      const auto m = decode<semx::odometry_t>(data, *size);
      if (!m || !accept_odometry(*m)) {
        ++r.malformed;
        continue;
      }
      vehicle = to_vehicle_state(*m);
    } else if (e->channel == semx::channels::PLAN_PATH) {
      const auto m = decode<semx::path_t>(data, *size);
      if (!m || !accept_path(*m)) {
        ++r.malformed;
        continue;
      }
      const Path path = to_path(*m);
      const double t = static_cast<double>(path.utime) * 1e-6;
      if (t < from || t >= to) continue;
      // As the controller: no trajectory without a map and a vehicle, nor for a path it rejects.
      if (!field || !vehicle || !check_path_start(path, vehicle->position, config.path).empty()) {
        ++r.skipped;
        continue;
      }
      r.paths.push_back(
          ReplayedPath{t, path.plan_id, path.waypoints.size(), generator.generate(path, *vehicle, *field)});
    }
  }
  r.session = session->summary();
  return r;
}

}  // namespace semx::controller
