#include "semx/controller/controller.hpp"

#include <algorithm>
#include <cmath>

#include "semx/core/text.hpp"

namespace semx::controller {
namespace {

int64_t micros(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

}  // namespace

Controller::Controller(const ControllerConfig& config)
    : config_(config), generator_(config), tracker_(config.tracking) {}

void Controller::reset() {
  pending_.reset();
  odometry_.reset();
  esdf_.reset();
  esdf_utime_ = 0;
  esdf_new_ = false;
  trajectory_.reset();
  error_sq_sum_ = 0;
  error_count_ = 0;
  status_ = ControllerStatus();
  counters_ = ControllerCounters();
  last_generation_ = GenerationResult();
}

void Controller::on_path(Path path) {
  ++counters_.paths;
  if (pending_) ++counters_.superseded;
  pending_ = std::move(path);
}

void Controller::on_esdf(std::shared_ptr<const DistanceField> field, int64_t utime) {
  esdf_ = std::move(field);
  esdf_utime_ = utime;
  esdf_new_ = true;
}

void Controller::on_odometry(const VehicleState& state) { odometry_ = state; }

std::string Controller::stale_reason(int64_t now) const {
  // Reasons carry the limits, not the ages, so the status does not "change" every step.
  if (!odometry_) return "no odometry yet";
  if (now - odometry_->utime > micros(config_.safety.max_odometry_age)) {
    return "odometry older than " + core::short_number(config_.safety.max_odometry_age) + " s";
  }
  if (!esdf_) return "no ESDF yet";
  if (now - esdf_utime_ > micros(config_.safety.max_esdf_age)) {
    return "ESDF older than " + core::short_number(config_.safety.max_esdf_age) + " s";
  }
  return "";
}

void Controller::stop(ControllerState state, const std::string& reason) {
  trajectory_.reset();
  status_.state = state;
  status_.reason = reason;
  status_.tracking_error = 0.0;
  status_.progress = 0.0;
}

void Controller::reject(const Path& path, const std::string& why, bool unsafe) {
  ++(unsafe ? counters_.unsafe : counters_.rejected);
  status_.plan_id = path.plan_id;
  stop(ControllerState::kRejected, "path " + std::to_string(path.plan_id) + ": " + why);
}

void Controller::process_path(int64_t now, StepOutput& out) {
  const Path path = std::move(*pending_);
  pending_.reset();
  if (now - path.utime > micros(config_.path.max_age)) {
    reject(path, "older than " + core::short_number(config_.path.max_age) + " s", false);
    return;
  }
  const std::string why = check_path_start(path, odometry_->position, config_.path);
  if (!why.empty()) {
    reject(path, why, false);
    return;
  }
  last_generation_ = generator_.generate(path, *odometry_, *esdf_);
  if (!last_generation_.ok) {
    reject(path, last_generation_.reason, true);
    return;
  }
  trajectory_ = last_generation_.trajectory;
  trajectory_->plan_id = path.plan_id;
  trajectory_->start_utime = now;
  ++counters_.trajectories;
  ++(trajectory_->optimized ? counters_.optimized : counters_.fallbacks);
  if (last_generation_.slowed) ++counters_.slowed;
  if (last_generation_.slowed && last_generation_.slow_zones > 0) ++counters_.slowed_near;
  counters_.squared_headings += last_generation_.squared_headings;
  counters_.repaired_headings += last_generation_.repaired_headings;
  if (!trajectory_->optimized) {
    switch (last_generation_.cause) {
      case FallbackCause::kStrays:
        ++counters_.fallback_strays;
        break;
      case FallbackCause::kTooClose:
        ++counters_.fallback_too_close;
        break;
      default:
        break;
    }
  }
  error_sq_sum_ = 0;
  error_count_ = 0;
  status_.plan_id = path.plan_id;
  status_.state = ControllerState::kTracking;
  status_.reason =
      trajectory_->optimized && !last_generation_.slowed ? "optimised trajectory" : last_generation_.reason;
  out.new_trajectory = &*trajectory_;
}

StepOutput Controller::step(int64_t now) {
  StepOutput out;
  const ControllerState before = status_.state;
  const int64_t plan_before = status_.plan_id;
  const std::string reason_before = status_.reason;

  const std::string stale = stale_reason(now);
  if (!stale.empty()) {
    if (status_.state != ControllerState::kStaleInput) ++counters_.stale_stops;
    stop(ControllerState::kStaleInput, stale);
  } else {
    if (status_.state == ControllerState::kStaleInput) stop(ControllerState::kIdle, "inputs fresh again");
    if (pending_) process_path(now, out);
    if (esdf_new_ && trajectory_ && status_.state == ControllerState::kTracking) {
      const double t = trajectory_->time_at(now);
      const ClearanceReport c = check_clearance(*trajectory_, *esdf_, t, t + config_.safety.check_horizon,
                                                generator_.flight_rule(trajectory_->optimized));
      if (!c.ok) {
        ++counters_.brakes;
        stop(ControllerState::kBraking, "predicted collision in " + core::short_number(c.violation_time - t) +
                                            " s: ESDF distance " + core::short_number(c.violation_distance) +
                                            " m");
      }
    }
    esdf_new_ = false;
  }

  if (trajectory_) {
    const double t = trajectory_->time_at(now);
    const double T = trajectory_->duration();
    status_.progress = T > 0 ? std::clamp(t / T, 0.0, 1.0) : 1.0;
    if (t < T) {
      const TrajectoryPoint ref = trajectory_->sample(t);
      out.command = tracker_.track(ref, *odometry_);
      status_.tracking_error = (ref.position - odometry_->position).norm();
      error_sq_sum_ += status_.tracking_error * status_.tracking_error;
      ++error_count_;
      status_.state = ControllerState::kTracking;
    } else {
      const Eigen::Vector3d end = trajectory_->end_position();
      out.command = tracker_.hold_at(end, trajectory_->end_yaw(), *odometry_);
      status_.tracking_error = (end - odometry_->position).norm();
      if (status_.state != ControllerState::kHolding) {
        status_.state = ControllerState::kHolding;
        status_.reason = "reached the end";
      }
    }
    status_.tracking_rms =
        error_count_ > 0 ? std::sqrt(error_sq_sum_ / static_cast<double>(error_count_)) : 0.0;
    const double lag = status_.tracking_error;
    if (config_.safety.max_tracking_error > 0.0 && lag > config_.safety.max_tracking_error) {
      ++counters_.off_track;
      stop(ControllerState::kBraking, core::short_number(lag) + " m from its reference (blocked or lagging)");
      out.command = TrackingController::hover(hover_yaw());
    }
  } else {
    out.command = TrackingController::hover(hover_yaw());
  }

  out.status = status_;
  out.status_changed =
      status_.state != before || status_.plan_id != plan_before || status_.reason != reason_before;
  return out;
}

}  // namespace semx::controller
