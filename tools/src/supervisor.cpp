#include "semx/tools/supervisor.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <vector>

#include "semx/runtime/config.hpp"
#include "semx/runtime/monotonic_clock.hpp"
#include "semx/runtime/parent_watch.hpp"
#include "semx/runtime/restart_count.hpp"
#include "semx/tools/process_usage.hpp"

namespace semx::tools {

namespace {

int g_signal_pipe[2] = {-1, -1};

extern "C" void on_supervisor_signal(int sig) {
  const int saved = errno;
  const char c = static_cast<char>(sig);
  [[maybe_unused]] ssize_t n = write(g_signal_pipe[1], &c, 1);
  errno = saved;
}

struct Child {
  const ProcessSpec* spec;
  pid_t pid = -1;
  int out_fd = -1;
  std::string partial;
  int restarts = 0;
  int in_a_row = 0;       // restarts since the last run that outlasted the backoff's cap
  double started_at = 0;  // when the running process was started
  double start_at = 0;    // when to (re)start, if pid < 0 and pending
  bool pending = true;
  bool finished = false;
  const char* color = "";
  std::unique_ptr<std::ofstream> log;  // log_dir/NAME.log, when the set has a log_dir
  std::deque<std::string> recent;      // last lines of a hidden process, shown if it fails
};

constexpr std::size_t kRecentLines = 15;

const char* kColors[] = {"\033[36m", "\033[32m", "\033[33m", "\033[35m", "\033[34m", "\033[91m", "\033[92m"};

std::string resolve_program(const std::string& program, const SupervisorOptions& o) {
  if (program.find('/') != std::string::npos) {
    return program[0] == '/' ? program : o.root_dir + "/" + program;
  }
  const std::string in_bin = o.bin_dir + "/" + program;
  struct stat st {};
  if (!o.bin_dir.empty() && stat(in_bin.c_str(), &st) == 0 && (st.st_mode & S_IXUSR)) return in_bin;
  return program;  // execvp searches PATH
}

class Supervisor {
 public:
  Supervisor(const LaunchSet& set, const SupervisorOptions& o) : set_(set), o_(o) {
    std::size_t width = 0;
    for (const auto& p : set.processes) width = std::max(width, p.name.size());
    width_ = width;
    int k = 0;
    const double t0 = semx::runtime::monotonic_s();
    const std::string log_dir = o.log_dir.empty() ? set.log_dir : o.log_dir;
    log_dir_ = log_dir;
    if (!log_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(log_dir, ec);
      if (ec) throw std::runtime_error("log directory '" + log_dir + "': " + ec.message());
    }
    for (const auto& d : set.dirs) {
      std::error_code ec;
      std::filesystem::create_directories(d, ec);
      if (ec) throw std::runtime_error("directory '" + d + "': " + ec.message());
    }
    for (const auto& p : set.processes) {
      Child c;
      c.spec = &p;
      c.start_at = t0 + p.start_delay_s;
      c.color = o.color ? kColors[k++ % 7] : "";
      if (!log_dir.empty()) {
        const std::string file = log_dir + "/" + p.name + ".log";
        c.log = std::make_unique<std::ofstream>(file, std::ios::app);
        if (!*c.log) throw std::runtime_error("cannot write process log '" + file + "'");
      }
      children_.push_back(std::move(c));
    }
  }

  int run() {
    const double t0 = semx::runtime::monotonic_s();
    say("set '" + set_.name + "': " + std::to_string(children_.size()) + " processes" +
        (o_.lcm_url.empty() ? "" : " on " + o_.lcm_url));
    while (true) {
      const double t = semx::runtime::monotonic_s();
      if (!stopping_ && o_.duration_s > 0 && t - t0 >= o_.duration_s) {
        say("duration of " + std::to_string(o_.duration_s) + " s reached");
        begin_stop(0);
      }
      if (!stopping_) {
        for (auto& c : children_) {
          if (c.pending && t >= c.start_at) start(c);
          if (stopping_) break;
        }
      }
      if (stopping_ && t >= kill_at_ && !killed_) {
        for (auto& c : children_) {
          if (c.pid > 0) {
            say(c, "did not stop within " + std::to_string(o_.grace_s) + " s: SIGKILL");
            kill(-c.pid, SIGKILL);
          }
        }
        killed_ = true;
      }
      bool any_alive = false, any_pending = false;
      for (const auto& c : children_) {
        any_alive |= c.pid > 0;
        any_pending |= c.pending && !stopping_;
      }
      if (!any_alive && (!any_pending || stopping_)) break;
      wait_io(stopping_ ? 50 : 100);
      reap();
    }
    for (auto& c : children_) flush(c);
    if (exit_code_ == 0) say("set '" + set_.name + "' ended");
    return exit_code_;
  }

 private:
  void say(const std::string& msg) { std::cout << "[semx-launch] " << msg << std::endl; }
  void say(const Child& c, const std::string& msg) { say(c.spec->name + ": " + msg); }

  void emit_line(Child& c, const std::string& line) {
    if (c.log) *c.log << line << "\n";
    if (!c.spec->show) {
      c.recent.push_back(line);
      if (c.recent.size() > kRecentLines) c.recent.pop_front();
      return;
    }
    print_line(c, line);
  }

  void print_line(const Child& c, const std::string& line) {
    std::string name = c.spec->name;
    name.resize(width_, ' ');
    std::cout << c.color << name << (o_.color ? "\033[0m" : "") << " | " << line << "\n";
  }

  void flush(Child& c) {
    if (c.out_fd >= 0) {
      drain(c);
      close(c.out_fd);
      c.out_fd = -1;
    }
    if (!c.partial.empty()) {
      emit_line(c, c.partial);
      c.partial.clear();
    }
    if (c.log) c.log->flush();
    std::cout.flush();
  }

  // A hidden process that failed: what it said last, so nobody has to look for the log.
  void show_recent(Child& c) {
    if (c.spec->show || c.recent.empty()) return;
    say(c, "its last lines:");
    for (const auto& line : c.recent) print_line(c, line);
    c.recent.clear();
  }

  void drain(Child& c) {
    char buf[4096];
    while (c.out_fd >= 0) {
      const ssize_t n = read(c.out_fd, buf, sizeof buf);
      if (n <= 0) {
        if (n == 0) {
          close(c.out_fd);
          c.out_fd = -1;
        }
        break;
      }
      c.partial.append(buf, static_cast<std::size_t>(n));
      std::size_t nl;
      while ((nl = c.partial.find('\n')) != std::string::npos) {
        emit_line(c, c.partial.substr(0, nl));
        c.partial.erase(0, nl + 1);
      }
      // A process that never ends its line must not grow us without bound.
      if (c.partial.size() > 65536) {
        emit_line(c, c.partial);
        c.partial.clear();
      }
    }
    std::cout.flush();
  }

  void start(Child& c) {
    c.pending = false;
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) {
      say(c, std::string("cannot create pipe: ") + std::strerror(errno));
      fail(c);
      return;
    }
    std::vector<std::string> argv_s = c.spec->command;
    argv_s[0] = resolve_program(argv_s[0], o_);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) {
      say(c, std::string("fork failed: ") + std::strerror(errno));
      close(fds[0]);
      close(fds[1]);
      fail(c);
      return;
    }
    if (pid == 0) {
      setpgid(0, 0);
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != parent) _exit(127);  // the supervisor died before prctl took effect
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      signal(SIGPIPE, SIG_DFL);
      sigset_t none;
      sigemptyset(&none);
      sigprocmask(SIG_SETMASK, &none, nullptr);
      dup2(fds[1], STDOUT_FILENO);
      dup2(fds[1], STDERR_FILENO);
      const int devnull = open("/dev/null", O_RDONLY);
      if (devnull >= 0) dup2(devnull, STDIN_FILENO);
      if (!o_.lcm_url.empty()) setenv("LCM_DEFAULT_URL", o_.lcm_url.c_str(), 1);
      // Every process records the configuration it runs with next to its log (runtime/config.hpp).
      if (!log_dir_.empty()) {
        setenv(runtime::kEffectiveConfigEnv, (log_dir_ + "/" + c.spec->name + ".config.yaml").c_str(), 1);
      }
      setenv(runtime::kRestartEnv, std::to_string(c.restarts).c_str(), 1);
      setenv(runtime::kSupervisorEnv, std::to_string(parent).c_str(), 1);
      for (const auto& [k, v] : c.spec->env) setenv(k.c_str(), v.c_str(), 1);
      std::vector<char*> argv;
      for (auto& a : argv_s) argv.push_back(a.data());
      argv.push_back(nullptr);
      execvp(argv[0], argv.data());
      dprintf(STDERR_FILENO, "cannot run '%s': %s\n", argv[0], std::strerror(errno));
      _exit(127);
    }
    setpgid(pid, pid);  // also here, so a signal sent right away reaches the group
    close(fds[1]);
    fcntl(fds[0], F_SETFL, O_NONBLOCK);
    c.pid = pid;
    c.out_fd = fds[0];
    c.started_at = semx::runtime::monotonic_s();
    say(c,
        (c.restarts > 0 ? "restarted (pid " : "started (pid ") + std::to_string(pid) + "): " + join(argv_s));
  }

  static std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& a : v) s += (s.empty() ? "" : " ") + a;
    return s;
  }

  void wait_io(int timeout_ms) {
    std::vector<pollfd> fds;
    fds.push_back({g_signal_pipe[0], POLLIN, 0});
    for (const auto& c : children_) {
      if (c.out_fd >= 0) fds.push_back({c.out_fd, POLLIN, 0});
    }
    const int n = poll(fds.data(), fds.size(), timeout_ms);
    if (n <= 0) return;
    if (fds[0].revents & POLLIN) {
      char sig[16];
      const ssize_t k = read(g_signal_pipe[0], sig, sizeof sig);
      for (ssize_t i = 0; i < k; ++i) {
        if (sig[i] == SIGINT || sig[i] == SIGTERM) {
          if (!stopping_) {
            say(std::string("caught ") + (sig[i] == SIGINT ? "SIGINT" : "SIGTERM") +
                ": stopping all processes");
            begin_stop(130);
            signalled_at_ = semx::runtime::monotonic_s();
          } else if (!killed_ &&
                     (signalled_at_ < 0 || semx::runtime::monotonic_s() - signalled_at_ > kSameSignalS)) {
            say("second signal: SIGKILL now");
            kill_at_ = 0;
          }
        }
      }
    }
    for (auto& c : children_) {
      if (c.out_fd >= 0) drain(c);
    }
  }

  void reap() {
    while (true) {
      int status = 0;
      struct rusage usage {};
      const pid_t pid = wait4(-1, &status, WNOHANG, &usage);
      if (pid <= 0) return;
      // What a process held at its largest (Linux: KiB) and the CPU it used: the figures
      // hostile-input campaigns, long runs and the bench's cost table report, read where they
      // cost nothing.
      const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + t.tv_usec * 1e-6; };
      const std::string peak = usage_text(ProcessUsage{static_cast<double>(usage.ru_maxrss) / 1024.0,
                                                       seconds(usage.ru_utime), seconds(usage.ru_stime)});
      for (auto& c : children_) {
        if (c.pid != pid) continue;
        c.pid = -1;
        flush(c);
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        const std::string how =
            (WIFEXITED(status) ? "exited with " + std::to_string(code)
                               : std::string("killed by signal ") + strsignal(WTERMSIG(status))) +
            peak;
        const ExitAction action = on_process_exit(*c.spec, code, c.restarts, stopping_);
        if (code != 0 && !stopping_) show_recent(c);
        switch (action) {
          case ExitAction::kRestart: {
            ++c.restarts;
            const double t = semx::runtime::monotonic_s();
            // A process that ran for a while was healthy: its next failure starts the backoff over.
            c.in_a_row = t - c.started_at > c.spec->restart_delay_max_s ? 1 : c.in_a_row + 1;
            const double delay = restart_delay(*c.spec, c.in_a_row);
            char when[32];
            std::snprintf(when, sizeof when, "%.2f", delay);
            say(c, how + ": restart " + std::to_string(c.restarts) + "/" +
                       std::to_string(c.spec->max_restarts) + " in " + when + " s");
            c.pending = true;
            c.start_at = t + delay;
            break;
          }
          case ExitAction::kFailSet:
            say(c, how + ": required process failed, stopping the set");
            begin_stop(1);
            break;
          case ExitAction::kEndSet:
            say(c, how + ": ends the set");
            begin_stop(0);
            break;
          case ExitAction::kContinue:
            say(c, how);
            c.finished = true;
            break;
        }
      }
    }
  }

  void fail(Child& c) {
    if (c.spec->required) {
      begin_stop(1);
    } else {
      c.finished = true;
    }
  }

  void begin_stop(int code) {
    if (stopping_) return;
    stopping_ = true;
    exit_code_ = code;
    kill_at_ = semx::runtime::monotonic_s() + o_.grace_s;
    for (auto& c : children_) {
      c.pending = false;
      if (c.pid > 0) kill(-c.pid, SIGINT);
    }
  }

  const LaunchSet& set_;
  SupervisorOptions o_;
  std::vector<Child> children_;
  std::size_t width_ = 0;
  std::string log_dir_;  // the set's log_dir (or --log-dir): where processes write their logs and configs
  bool stopping_ = false;
  bool killed_ = false;
  // A Ctrl-C reaches both a wrapper script and the launcher, and the script passes it on: a signal
  // this soon after the first is that one again, not a second Ctrl-C.
  static constexpr double kSameSignalS = 0.5;
  double signalled_at_ = -1;
  double kill_at_ = 0;
  int exit_code_ = 0;
};

}  // namespace

int run_launch_set(const LaunchSet& set, const SupervisorOptions& options) {
  if (g_signal_pipe[0] < 0) {
    if (pipe2(g_signal_pipe, O_CLOEXEC | O_NONBLOCK) != 0)
      throw std::runtime_error("cannot create signal pipe");
  }
  struct sigaction sa {};
  sa.sa_handler = on_supervisor_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
  return Supervisor(set, options).run();
}

}  // namespace semx::tools
