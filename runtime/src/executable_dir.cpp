#include "semx/runtime/executable_dir.hpp"

#include <unistd.h>

#include <climits>
#include <filesystem>

namespace semx::runtime {

std::string executable_dir() {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  buf[n] = '\0';
  return std::filesystem::path(buf).parent_path().string();
}

}  // namespace semx::runtime
