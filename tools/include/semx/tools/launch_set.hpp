// A process set: which semx processes to start together, how, and what to do when one exits.
// Format: docs/launch.md. Logic only; tools/src/supervisor.cpp runs a set.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace semx::tools {

enum class RestartPolicy { kNever, kOnFailure, kAlways };

struct ProcessSpec {
  std::string name;
  std::vector<std::string> command;  // argv after substitution; command[0] resolved later
  RestartPolicy restart = RestartPolicy::kNever;
  int max_restarts = 3;
  // procman's backoff: the n-th restart in a row waits restart_delay_s * 2^(n-1), at most
  // restart_delay_max_s; a run that lasted longer than restart_delay_max_s starts the doubling over.
  double restart_delay_s = 1.0;
  double restart_delay_max_s = 30.0;
  bool required = true;      // its failure (after restarts) fails the whole set
  bool ends_set = false;     // its successful exit ends the whole set (e.g. the clock after N ticks)
  double start_delay_s = 0;  // wall seconds after the set starts
  // false: its lines go to the set's log only (the console shows the last of them if it fails),
  // so a set can show one progress line per process that matters.
  bool show = true;
  std::map<std::string, std::string> env;
};

struct LaunchSet {
  std::string name;
  std::string description;
  std::string file;
  std::map<std::string, std::string> args;  // after overrides
  std::string log_dir;  // every process's output also goes to log_dir/NAME.log (empty: none)
  std::vector<std::string> dirs;  // created before any process starts (where they keep state)
  std::vector<ProcessSpec> processes;
};

// Loads a set file. `${name}` in commands and env values is replaced by the set's args (its
// `args:` defaults, overridden by `overrides`), then by `builtins` (root, bin, ...), then by the
// environment; an unknown name or override is an error naming the file and line.
LaunchSet load_launch_set(const std::string& file, const std::map<std::string, std::string>& overrides,
                          const std::map<std::string, std::string>& builtins);

// Replaces ${name} in `text`; throws std::runtime_error("unknown variable ...") otherwise.
std::string substitute(const std::string& text, const std::map<std::string, std::string>& vars);

enum class ExitAction {
  kRestart,   // start it again after restart_delay_s
  kFailSet,   // stop everything, the set failed
  kEndSet,    // stop everything, the set is done
  kContinue,  // let the others run on
};

// What to do when `spec`'s process exited with `exit_code` (128 + signal for a signal) after
// `restarts` restarts; `stopping` is true once the set is being stopped anyway.
ExitAction on_process_exit(const ProcessSpec& spec, int exit_code, int restarts, bool stopping);

// Seconds before the `in_a_row`-th consecutive restart (1 for the first): the backoff above.
double restart_delay(const ProcessSpec& spec, int in_a_row);

}  // namespace semx::tools
