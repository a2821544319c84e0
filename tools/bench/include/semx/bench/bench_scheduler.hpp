// Runs a bench plan (bench_plan.hpp): each run is `semx-launch demo` (./semx demo's process set) on
// one of N slots, slot k on the base URL's port + k (LCM_DEFAULT_URL's, else 7667), writing its run folder
// DIR/runs/NAME; one result line per run from its metrics.csv; runs whose folder has metrics.json are kept;
// Ctrl-C lets the running sets stop (the terminal's SIGINT reaches their launchers too) and starts no more.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "semx/bench/bench_plan.hpp"

namespace semx::bench {

struct SchedulerOptions {
  std::string out_dir;   // DIR: the run folders go to DIR/runs/NAME
  std::string launcher;  // the semx-launch executable
  int slots = 1;         // --jobs
  // Slot k's process set talks on this URL with its port + k (slot_lcm_url).
  std::string base_url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
  bool keep_logs = false;  // keep run.lcmlog (and start the set's logger at all)
  std::string clock = "lockstep";
  std::vector<std::string> launch_args;      // --arg KEY=VALUE, after the bench's own
  std::string snmp_path = "/proc/net/snmp";  // where the kernel's UDP counters are read
};

// The process set's LCM provider on a slot: `base_url` (udpm://ADDR:PORT?OPTS) on PORT + slot,
// with the receive buffer the demo uses added when OPTS has none (without it the mapper of a
// lockstep run integrated 406 of 1149 depth frames). With `port` >= 0 that port replaces the
// URL's. Throws runtime::ArgError for a URL that is not udpm with a port, or ports past 65535.
std::string slot_lcm_url(const std::string& base_url, int slot, int port = -1);

// semx-launch's argv (without the program) for one run in `dir` on `slot`.
std::vector<std::string> launch_argv(const BenchRun& run, int slot, const std::string& dir,
                                     const SchedulerOptions& o);

// UDP datagrams the kernel dropped for full receive buffers, machine-wide: RcvbufErrors of the
// "Udp:" lines of /proc/net/snmp, found by the header (the column order is the kernel's). Empty
// where the file or the counter is missing. A lockstep run is the same every time only if every
// message arrives, so a run during which this grew may not reproduce.
std::optional<int64_t> udp_rcvbuf_errors(const std::string& snmp_path);

// When the counter grew from `before` to `after`: writes the count to DIR/udp_drops.txt and
// returns the warning line, which starts with `prefix`; else nothing.
std::optional<std::string> udp_drop_warning(std::optional<int64_t> before, std::optional<int64_t> after,
                                            const std::string& dir, const std::string& prefix);

// A finished run's line from its metrics.csv text ("[K/TOTAL] NAME: coverage 98.8 %, Time_f ...
// (S s so far)"); nothing when the text has no data row.
std::optional<std::string> result_line(int k, int total, const std::string& name,
                                       const std::string& metrics_csv, int64_t elapsed_s);

// Runs every run of `runs` whose folder has no metrics.json, `o.slots` at a time, in order,
// printing to `out` a line per run as it ends (or "done before, kept"). Returns 130 when SIGINT
// came (the runs already started are waited for), else 0; a SIGINT ignored on entry stays
// ignored. Elapsed seconds count from `t0_s`, a steady_clock time in seconds.
int run_bench(const std::vector<BenchRun>& runs, const SchedulerOptions& o, std::ostream& out, double t0_s);

}  // namespace semx::bench
