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

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()), cpu_start_(thread_cpu_ms()) {}
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  }
  double s() const { return 1e-3 * ms(); }
  double cpu_ms() const { return thread_cpu_ms() - cpu_start_; }

 private:
  std::chrono::steady_clock::time_point start_;
  double cpu_start_;
};

}  // namespace semx::core
