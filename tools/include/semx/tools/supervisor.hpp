// Runs a LaunchSet: starts each process in its own process group, prefixes every line it
// prints with its name, applies the restart policy, and stops everything (SIGINT, then SIGKILL
// after a grace period) on Ctrl-C, on a failed required process, or when the set ends.
// Children also get SIGTERM if the supervisor itself dies (PR_SET_PDEATHSIG), so no process is
// ever left behind.
#pragma once

#include <string>

#include "semx/tools/launch_set.hpp"

namespace semx::tools {

struct SupervisorOptions {
  std::string bin_dir;    // where semx executables live (command[0] without '/' is looked up here first)
  std::string root_dir;   // relative command paths resolve against it
  std::string lcm_url;    // exported as LCM_DEFAULT_URL to every process, if not empty
  double duration_s = 0;  // stop the set after this many wall seconds (0: never)
  double grace_s = 5.0;   // SIGINT -> SIGKILL
  bool color = false;
  std::string log_dir;    // overrides the set's log_dir
};

// Returns the exit code of the set: 0 ended normally (or --duration), 1 a required process
// failed or could not start, 130 interrupted by SIGINT/SIGTERM.
int run_launch_set(const LaunchSet& set, const SupervisorOptions& options);

}  // namespace semx::tools
