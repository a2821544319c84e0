// semx-eval: a run's metrics from an lcm-logger log alone (no network, no processes): the log's
// MAP_UPDATE/MAP_SNAPSHOT rebuild the mapper's map in a MapMirror, and its ODOMETRY, SIM_EVENT,
// PLANNER_STATUS and SIM_CLOCK drive the same Evaluation as the live evaluator, with the same
// rule for map messages (held until the SIM_CLOCK tick after their utime, as the lockstep
// evaluator's MapClient holds them), so a lockstep run and its log give the same figures.
//
// The log is scanned first (runtime::scan_log: LCM 1.3.1's reader asserts on corrupt headers);
// only the complete events are read. Every event goes through the same wire validation and
// decoding as a live subscription; malformed ones are counted and skipped.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "semx/evaluator/evaluation.hpp"
#include "semx/map/map_mirror.hpp"
#include "semx/runtime/log_scan.hpp"
#include "semx/runtime/log_session.hpp"

namespace semx::evaluator {

class LogEvalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LogEvalOptions {
  std::string log_path;
  // World file or shipped name; "" takes the name the simulator gave in SIM_EVENT EPISODE_START.
  std::string world;
  // A given world whose name differs from the one the log's EPISODE_START names is refused (the
  // coverage of one world's log against another's truth is a number that means nothing), unless
  // this is set.
  bool any_world = false;
  // The run's key, to check every event's tag; "" takes session.key beside the log if there is
  // one, else reads the session of the log's first EPISODE_START unchecked (log_session.hpp).
  std::string auth_key_file;
  EvaluationOptions evaluation;  // info (planner, seed, samples), time limit, resolution
};

struct LogEvalReport {
  runtime::LogLayout layout;
  std::map<std::string, int64_t> channels;  // events read, per channel
  int64_t events_read = 0;
  int64_t malformed = 0;  // events on a semx channel that failed validation or decoding
  std::string first_error;
  bool clock = false;       // the log has SIM_CLOCK
  int64_t map_gaps = 0;     // times the mirror lost the sequence (needs a snapshot)
  double log_wall_s = 0.0;  // logger time from the first event to the last one read
  bool verified = false;    // every event's tag checked with the run's key
  std::string left_out;     // another set's or refused events (LogSession::summary), "" if none
};

class LogEvaluator {
 public:
  // Throws LogEvalError (bad log, no world) or the world loader's error.
  explicit LogEvaluator(LogEvalOptions options);
  ~LogEvaluator();
  LogEvaluator(LogEvaluator&&) noexcept;
  LogEvaluator& operator=(LogEvaluator&&) noexcept;

  // Reads the log and ends the run (at the planner's DONE, the time limit, EPISODE_END or the
  // log's end). Call once.
  void run();

  const Evaluation& evaluation() const { return *evaluation_; }
  const LogEvalReport& report() const { return report_; }
  // The map rebuilt from the log (an empty map before any map message).
  const map::StateGrid& grid() const;
  const std::string& world_path() const { return world_path_; }

  // Writes the run folder: the metrics files and map.png. Returns the paths written.
  std::vector<std::string> write_folder(const std::string& dir) const;

 private:
  struct Held;
  void apply(const Held& h);
  void observe(int64_t utime);
  void flush(int64_t before_utime);

  LogEvalOptions options_;
  std::string world_path_;
  std::unique_ptr<Evaluation> evaluation_;
  std::unique_ptr<map::MapMirror> mirror_;
  std::unique_ptr<map::StateGrid> empty_;
  std::vector<Held> held_;
  std::unique_ptr<runtime::LogSession> session_;
  LogEvalReport report_;
  bool ran_ = false;
};

// The world a log names: the description of its first SIM_EVENT EPISODE_START of the run's
// session ("" if none).
std::string world_named_in_log(const std::string& log_path, const runtime::LogLayout& layout,
                               runtime::LogSession& session);

}  // namespace semx::evaluator
