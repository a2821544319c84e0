// A process semx-launch started stops when the launcher is gone. The launcher asks the kernel
// for that (PR_SET_PDEATHSIG), but once, under load, a semx-clock kept running for 13 minutes
// after its launcher was killed with SIGKILL (Processes.LauncherKilledHardTakesItsChildrenWithIt;
// the cause was not found). So the launcher also sets SEMX_SUPERVISOR_PID in each child's
// environment, and a node that has it checks, with each NODE_STATUS, that its parent is still the
// process that started it: when the parent dies, the kernel hands the child to another (init or
// a subreaper), and the node stops. The node compares with the parent it started with, not with
// the variable's value (the launcher's pid, for whoever reads the environment), so a command the
// launcher runs through a shell is watched too. A node started by hand (no variable) is never
// stopped this way: its shell may come and go (nohup).
#pragma once

#include <sys/types.h>

namespace semx::runtime {

inline constexpr const char* kSupervisorEnv = "SEMX_SUPERVISOR_PID";

class ParentWatch {
 public:
  // Reads the environment and the parent now.
  ParentWatch();
  bool armed() const { return parent_ > 0; }
  // True once the parent the process started with is gone (never when not armed).
  bool parent_gone() const;
  pid_t parent() const { return parent_; }

 private:
  pid_t parent_ = -1;
};

}  // namespace semx::runtime
