#include "semx/runtime/parent_watch.hpp"

#include <unistd.h>

#include <cstdlib>

namespace semx::runtime {

ParentWatch::ParentWatch() {
  const char* v = std::getenv(kSupervisorEnv);
  if (v && *v) parent_ = getppid();
}

bool ParentWatch::parent_gone() const { return armed() && getppid() != parent_; }

}  // namespace semx::runtime
