// Where this process's executable lies: every semx executable is built into one folder, so a
// tool finds the others (semx-launch, semx-bench-report, semx-simulator) beside itself.
#pragma once

#include <string>

namespace semx::runtime {

// The folder of /proc/self/exe; "." when it cannot be read.
std::string executable_dir();

}  // namespace semx::runtime
