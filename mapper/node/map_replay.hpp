// Rebuilding a map from an lcm-logger log (semx-map-replay): every CAMERA_DEPTH event is
// decoded and checked exactly as the mapper node does and integrated into a Mapper, with no
// network and as fast as the frames integrate.
//
// Logs are read with lcm::LogFile, after a scan of the event headers: LCM 1.3.1's reader asserts
// or allocates blindly on a corrupt header, so a file that is not a log, or is corrupt in the
// middle, is refused with the byte offset of the problem before LCM reads it. A log whose last
// event was cut short (lcm-logger killed while writing) is read up to that event, with a warning.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "semx/mapper/mapper.hpp"
#include "semx/runtime/log_scan.hpp"

namespace semx::mapper {

// What replay_log throws: the log's scan errors (runtime::scan_log) and its own.
using ReplayError = runtime::LogError;

struct ReplayOptions {
  std::string log_path;
  std::string channel = "CAMERA_DEPTH";
  std::string auth_key_file;  // "" : session.key beside the log, if any (runtime/log_session.hpp)
};

struct ReplayReport {
  runtime::LogLayout layout;
  std::map<std::string, int64_t> channels;  // events per channel
  int64_t depth_events = 0;
  int64_t integrated = 0;
  int64_t rejected = 0;   // decoded frames the integrator refused (reason in first_error)
  int64_t malformed = 0;  // events that are not a valid depth_image_t or not a plausible frame
  int64_t skipped = 0;    // not due (integration.frame_period_s), as the live mapper skips them
  std::string left_out;   // another set's or refused events (LogSession::summary), "" if none
  std::string first_error;
  int64_t first_utime = -1;
  int64_t last_utime = -1;
  double integrate_s = 0.0;  // wall time spent in Mapper::integrate
};

// Integrates the log's frames into `mapper`, one per integration.frame_period_s as the live node
// does. Throws ReplayError (see scan_log).
ReplayReport replay_log(const ReplayOptions& options, Mapper& mapper);

// Writes <dir>/map.ckpt (a checkpoint semx-mapper --checkpoint can start from), <dir>/map.bt
// (OctoMap, octovis) and <dir>/map.pcd (occupied voxel centres, pcl_viewer), creating `dir`.
// Returns the paths written; throws MapIoError naming the file on failure.
std::vector<std::string> write_map_files(const Mapper& mapper, const std::string& dir, int64_t utime);

}  // namespace semx::mapper
