#include "semx/runtime/restart_count.hpp"

#include <cerrno>
#include <climits>
#include <cstdlib>

namespace semx::runtime {

int restart_count() {
  const char* v = std::getenv(kRestartEnv);
  if (!v || !*v) return 0;
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(v, &end, 10);
  if (errno != 0 || *end != '\0' || n < 0 || n > INT_MAX) return 0;
  return static_cast<int>(n);
}

}  // namespace semx::runtime
