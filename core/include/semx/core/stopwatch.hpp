// Wall and thread-CPU time of a piece of work, for status messages and benchmarks only:
// decisions use message time (DESIGN.md §3). CPU time is what the work costs on one core
// whatever else the machine is doing.
#pragma once

#include <time.h>

#include <chrono>

namespace semx::core {

inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// Wall time only: a steady_clock read is a vDSO call, while the thread's CPU clock is a system
// call (~1 us in a VM), which DEP's per-sample watches made 5 % of its cycle.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  }
  double s() const { return 1e-3 * ms(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Wall and thread-CPU time, for whole cycles.
class CpuStopwatch : public Stopwatch {
 public:
  CpuStopwatch() : cpu_start_(thread_cpu_ms()) {}
  double cpu_ms() const { return thread_cpu_ms() - cpu_start_; }

 private:
  double cpu_start_;
};

}  // namespace semx::core
