// The bench's plan (docs/evaluation.md, "The main job and the paper's experiment"): its flags, their
// checks and the runs in the order they start, with their names and time limits. No processes,
// no LCM: semx-bench (bench_scheduler.hpp) runs the plan.
//
// The bench was a bash function of ./semx; its users' flags, errors and dry-run lists stay the
// same. That is why values are kept as the text given (`--samples 045` names runs "s045", as
// before) and why lists split and match as bash did (list_words, time_limit_of).
#pragma once

#include <string>
#include <vector>

namespace semx::bench {

// The flags of ./semx bench, as given. parse_bench_args applies them in order, so a later flag
// overrides an earlier one (`--quick --worlds env2` runs env2, `--worlds env2 --quick` env1).
struct BenchOptions {
  std::string worlds = "env1,env2,env3";
  std::string planners = "nbv,aep,dep,semantic-dep,fuel,oracle";
  std::string seeds = "3";
  std::string sweep = "paper";  // a comma list, "" for none, or "paper": Table II's rows per world
  std::string samples = "45";   // the density of the planner comparison
  std::string time_limits = "env1=300,env2=600,env3=900";  // NAME=S,...; "*" matches every world
  std::string out;                                         // empty: runs/bench-DATE
  std::string against;  // another bench's folder: the report pairs the runs with its (against.md)
  bool keep_logs = false;
  std::string clock = "lockstep";
  std::string jobs;       // "": one set a core (default_job_count)
  std::string base_port;  // "": the port of LCM_DEFAULT_URL (else 7667); slot k uses it + k
  bool dry_run = false;
  bool help = false;                     // --help was given: print bench_help() and nothing else
  std::vector<std::string> launch_args;  // --arg KEY=VALUE, to every run's process set
};

// The process-set args the bench sets itself, which --arg may not.
const std::vector<std::string>& reserved_launch_args();

// Applies `args` (the words after `./semx bench`) to the defaults. Throws runtime::ArgError with
// the message ./semx prints after "semx: bench: " (an unknown flag, a flag without its value, an
// --arg the bench sets itself or without '='). Stops at --help.
BenchOptions parse_bench_args(const std::vector<std::string>& args);

// The checks after parsing, in the order of the bash bench (so one command gives one message):
// --seeds, --samples, --jobs positive integers, --planners known, --sweep positive integers,
// --worlds env1..3, "generated" or files. Throws runtime::ArgError.
void validate_bench_options(const BenchOptions& o);

// --seeds and --jobs as numbers (after validate_bench_options).
int seed_count(const BenchOptions& o);
int job_count(const BenchOptions& o);
// Without --jobs: one process set per core, at most 8. The machine is saturated then (a set alone
// waits for acks part of the time; two on two cores keep both busy), and each set holds up to
// about 1 GB (the oracle's view cache), which 8 sets keep within a workstation's memory.
int default_job_count();

// The words of a list as bash split `${list//,/ }`: commas and blanks separate, empty words
// vanish, and a word with a glob character is replaced by the paths it matches (kept as it is
// when none does), so `--worlds 'gen/*.yaml'` still means every world file there.
std::vector<std::string> list_words(const std::string& list);

// A world's name: env1, or a file's name without directory and ".yaml" (basename W .yaml).
std::string world_name(const std::string& world);

// A world's time limit in simulated seconds, as the text of `time_limits` gives it: the last
// "NAME=S" with S made of digits and dots, else the last "*=S", else "600".
std::string time_limit_of(const std::string& time_limits, const std::string& world);

// A world's sampling densities: `sweep` itself unless it is "paper", which gives Table II's rows:
// env1 and env2 25..45, env3 30..50, any other world 25..50.
std::string sweep_of(const std::string& sweep, const std::string& world);

// `--worlds generated`: a fixed set of generated apartments (semx-world gen) from 50 to 600 m² and
// 1 to 14 rooms, the same for everyone who runs it: nobody tuned a planner to them, and they
// span the sizes env1-3 do not. semx-bench writes them to DIR/worlds/NAME.yaml before the runs
// (the generator is deterministic per seed, so the files are the same on every machine).
struct GeneratedWorld {
  int seed = 0;
  int area_m2 = 0;
  int rooms = 0;
  std::string time_limit;    // simulated s when --time-limits names neither it nor "*"
  std::string name() const;  // generated-sSEED-aAREA-rROOMS, the generator's own world name
};
const std::vector<GeneratedWorld>& generated_worlds();
// The word of --worlds that stands for them.
inline constexpr const char* kGeneratedWorlds = "generated";

struct BenchRun {
  std::string world;  // as given: env1 or a path
  std::string planner;
  std::string samples;  // as given
  int seed = 1;
  std::string time_limit;  // simulated s, time_limit_of's text

  // WORLDNAME-PLANNER-sSAMPLES-seedN, also the run's folder under DIR/runs.
  std::string name() const;
};

// The runs in the order they start. Worlds with the longest time limit first (ties in the order
// given), so that with --jobs N the short runs fill the end instead of one long run finishing
// alone on a half-idle machine; per world and seed the comparison (--planners at --samples),
// then semantic-dep at the rest of the world's sweep (its --samples entry is the comparison's
// run when semantic-dep is compared).
// `generated_dir` is where the generated worlds' files are (or will be) written.
std::vector<BenchRun> bench_runs(const BenchOptions& o, const std::string& generated_dir = "worlds");

// The generated worlds a plan needs (those of `--worlds generated`), in their order.
std::vector<GeneratedWorld> generated_worlds_of(const BenchOptions& o);

// "[K/TOTAL] NAME: time limit S s", one line per run: what --dry-run prints.
std::string dry_run_text(const std::vector<BenchRun>& runs);

// ./semx bench --help.
std::string bench_help();

}  // namespace semx::bench
