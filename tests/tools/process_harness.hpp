// Helpers for tests that run real semx processes over udpm on a port of their own.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "semx/runtime/lcm_url.hpp"

namespace semx::testing {

inline std::string bin(const std::string& name) { return std::string(SEMX_BIN_DIR) + "/" + name; }

// A port no other test (or concurrent run) uses: tests differ by `offset`, runs by pid.
inline int test_port(int offset) { return 20000 + (static_cast<int>(getpid()) % 2000) * 10 + offset; }

// A child process with its stdout+stderr captured to a file.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::string& log_file,
          const std::string& lcm_url = "") {
    pid_ = fork();
    if (pid_ == 0) {
      setpgid(0, 0);
      FILE* f = std::fopen(log_file.c_str(), "w");
      if (f) {
        dup2(fileno(f), STDOUT_FILENO);
        dup2(fileno(f), STDERR_FILENO);
      }
      if (!lcm_url.empty()) setenv("LCM_DEFAULT_URL", lcm_url.c_str(), 1);
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~Process() {
    if (pid_ > 0 && !exited_) {
      kill(-pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }
  bool alive() {
    if (exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    return !exited_;
  }
  // Waits up to `timeout_s`; returns the exit code, or -1 if still running.
  int wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (alive() && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return exited_ ? code_ : -1;
  }
  void signal(int sig) { kill(pid_, sig); }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int code_ = -1;
};

// Running (a zombie waiting for a reaper counts as gone: it runs no code and holds no socket).
inline bool pid_alive(pid_t pid) {
  if (kill(pid, 0) != 0) return false;
  FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (!f) return false;
  char state = '?';
  const int n = std::fscanf(f, "%*d (%*[^)]) %c", &state);
  std::fclose(f);
  return n == 1 && state != 'Z';
}

}  // namespace semx::testing
