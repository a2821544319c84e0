#include "semx/bench/bench_scheduler.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "semx/runtime/args.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/monotonic_clock.hpp"

namespace semx::bench {

namespace fs = std::filesystem;

namespace {

// True when metrics.json says the run ended as a run ends (DONE, the time limit or the episode's
// end), not stopped or still running: the evaluator writes the file on a Ctrl-C too.
bool run_finished(const std::string& metrics) {
  try {
    const YAML::Node m = YAML::LoadFile(metrics);  // JSON is YAML
    const std::string t = m["termination"] ? m["termination"].as<std::string>() : "";
    return t == "planner_done" || t == "time_limit" || t == "episode_end";
  } catch (const YAML::Exception&) {
    return false;  // unreadable: not a run that ended
  }
}

// Moves DIR/runs/NAME to the first free DIR/interrupted/NAME-K and returns that path.
std::string set_aside(const std::string& out_dir, const std::string& name) {
  fs::create_directories(out_dir + "/interrupted");
  for (int k = 1;; ++k) {
    const std::string to = out_dir + "/interrupted/" + name + "-" + std::to_string(k);
    if (!fs::exists(to)) {
      fs::rename(out_dir + "/runs/" + name, to);
      return to;
    }
  }
}

// SIGINT and SIGCHLD wake the scheduler through this pipe, so it can block in poll() without a
// signal slipping in between a check and the wait.
int g_wake[2] = {-1, -1};
volatile sig_atomic_t g_interrupted = 0;

extern "C" void on_bench_signal(int sig) {
  const int saved = errno;
  if (sig == SIGINT) g_interrupted = 1;
  const char c = static_cast<char>(sig);
  [[maybe_unused]] const ssize_t n = write(g_wake[1], &c, 1);
  errno = saved;
}

// The handlers for the time of one run_bench; the previous ones come back after it.
class SignalScope {
 public:
  SignalScope() {
    if (g_wake[0] < 0 && pipe2(g_wake, O_CLOEXEC | O_NONBLOCK) != 0) {
      throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
    }
    g_interrupted = 0;
    struct sigaction sa {};
    sa.sa_handler = on_bench_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    // A SIGINT ignored on entry stays ignored (a bench started with `&` from a script), as a
    // shell keeps it and as the bash bench did.
    sigaction(SIGINT, nullptr, &old_int_);
    if (old_int_.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, nullptr);
    sa.sa_flags = SA_RESTART | SA_NOCLDSTOP;
    sigaction(SIGCHLD, &sa, &old_chld_);
  }
  ~SignalScope() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGCHLD, &old_chld_, nullptr);
  }
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

  static bool interrupted() { return g_interrupted != 0; }
  // Blocks until a signal came (or one came since the last call).
  static void wait() {
    pollfd p{g_wake[0], POLLIN, 0};
    while (poll(&p, 1, -1) < 0 && errno == EINTR) {
    }
    char buf[64];
    while (read(g_wake[0], buf, sizeof buf) > 0) {
    }
  }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_chld_ {};
};

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = s.find(sep, begin);
    parts.push_back(s.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

// Records as awk reads them: a final newline ends the last record rather than starting another.
std::vector<std::string> lines_of(const std::string& text) {
  if (text.empty()) return {};
  auto lines = split(text, '\n');
  if (text.back() == '\n') lines.pop_back();
  return lines;
}

// Blank-separated fields, as awk's default FS splits them.
std::vector<std::string> blank_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

// A field as awk's printf takes it for %f: its leading decimal number, 0 when it has none.
double awk_number(const std::string& s) {
  std::size_t b = 0;
  while (b < s.size() && (s[b] == ' ' || s[b] == '\t')) ++b;
  std::size_t e = b;
  auto digits = [&] {
    while (e < s.size() && s[e] >= '0' && s[e] <= '9') ++e;
  };
  if (e < s.size() && (s[e] == '+' || s[e] == '-')) ++e;
  digits();
  if (e < s.size() && s[e] == '.') {
    ++e;
    digits();
  }
  if (e < s.size() && (s[e] == 'e' || s[e] == 'E')) {
    std::size_t x = e + 1;
    if (x < s.size() && (s[x] == '+' || s[x] == '-')) ++x;
    if (x < s.size() && s[x] >= '0' && s[x] <= '9') {
      e = x;
      digits();
    }
  }
  return std::strtod(s.substr(b, e - b).c_str(), nullptr);
}

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string run_tag(int k, int total, const std::string& name) {
  return "[" + std::to_string(k) + "/" + std::to_string(total) + "] " + name;
}

struct Active {
  pid_t pid = 0;  // 0: the slot is free
  int k = 0;
  std::string name, dir;
  std::optional<int64_t> drops_before;
};

}  // namespace

std::string slot_lcm_url(const std::string& base_url, int slot, int port) {
  const std::string scheme = "udpm://";
  const std::size_t q = base_url.find('?');
  const std::string address = base_url.substr(0, q);
  std::string opts = q == std::string::npos ? "" : base_url.substr(q + 1);
  const std::size_t colon = address.rfind(':');
  if (address.rfind(scheme, 0) != 0 || colon == std::string::npos || colon < scheme.size()) {
    throw runtime::ArgError("LCM URL '" + base_url +
                            "': the bench needs udpm://ADDRESS:PORT (one port per slot)");
  }
  int base = port;
  if (base < 0) {
    const std::string digits = address.substr(colon + 1);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 5) {
      throw runtime::ArgError("LCM URL '" + base_url + "': '" + digits + "' is not a port");
    }
    base = std::stoi(digits);
  }
  if (base + slot > 65535) {
    throw runtime::ArgError("LCM port " + std::to_string(base) + " + slot " + std::to_string(slot) +
                            " is past 65535");
  }
  return runtime::with_receive_buffer(address.substr(0, colon + 1) + std::to_string(base + slot) +
                                      (opts.empty() ? "" : "?" + opts));
}

std::vector<std::string> launch_argv(const BenchRun& run, int slot, const std::string& dir,
                                     const SchedulerOptions& o) {
  std::vector<std::string> argv = {"demo"};
  // Without logs, no logger either: it reads every message of the run only to write a log the
  // bench would delete.
  if (!o.keep_logs) argv.insert(argv.end(), {"--without", "logger"});
  // The run's key stays in its folder, so its log can be checked and replayed (./semx eval).
  argv.insert(argv.end(),
              {"--no-color", "--lcm-url", slot_lcm_url(o.base_url, slot), "--key-out", dir + "/session.key"});
  for (const std::string& a :
       {"world=" + run.world, "planner=" + run.planner, "seed=" + std::to_string(run.seed),
        "samples=" + run.samples, "clock=" + o.clock, "time_limit=" + run.time_limit, "out=" + dir,
        std::string("progress=0")}) {
    argv.insert(argv.end(), {"--arg", a});
  }
  for (const auto& a : o.launch_args) argv.insert(argv.end(), {"--arg", a});
  return argv;
}

std::optional<int64_t> udp_rcvbuf_errors(const std::string& snmp_path) {
  std::ifstream f(snmp_path);
  if (!f) return std::nullopt;
  bool header = false;
  std::size_t column = 0;  // 0: no such counter
  std::vector<std::string> values;
  for (std::string line; std::getline(f, line);) {
    const auto fields = blank_fields(line);
    if (fields.empty() || fields[0] != "Udp:") continue;
    if (!header) {
      for (std::size_t i = 1; i < fields.size(); ++i) {
        if (fields[i] == "RcvbufErrors") column = i;
      }
      header = true;
    } else if (column > 0) {
      values.push_back(column < fields.size() ? fields[column] : "");
    }
  }
  // One number, or nothing the warning could compare (as `[ "$2" -gt "$1" ]` would refuse it).
  if (values.size() != 1 || values[0].empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(values[0].c_str(), &end, 10);
  if (errno != 0 || *end != '\0') return std::nullopt;
  return v;
}

std::optional<std::string> udp_drop_warning(std::optional<int64_t> before, std::optional<int64_t> after,
                                            const std::string& dir, const std::string& prefix) {
  if (!before || !after || *after <= *before) return std::nullopt;
  const std::string n = std::to_string(*after - *before);
  std::ofstream(dir + "/udp_drops.txt") << n << "\n";
  return prefix + ": warning: the kernel dropped " + n +
         " UDP datagrams during the run (RcvbufErrors, machine-wide): its figures may differ from a rerun";
}

std::optional<std::string> result_line(int k, int total, const std::string& name,
                                       const std::string& metrics_csv, int64_t elapsed_s) {
  const auto lines = lines_of(metrics_csv);
  if (lines.size() < 2) return std::nullopt;
  // metrics.csv: world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s,...
  const auto fields = split(lines[1], ',');
  auto field = [&](std::size_t i) { return i <= fields.size() ? fields[i - 1] : std::string(); };
  const std::string time_r = field(8).empty() ? "N/A" : format("%.1f s", awk_number(field(8)));
  return run_tag(k, total, name) + ": coverage " + format("%.1f", awk_number(field(7))) + " %, Time_f " +
         format("%.1f", awk_number(field(5))) + " s, Time_r " + time_r + ", distance " +
         format("%.1f", awk_number(field(6))) + " m, collisions " + field(9) + ", wall " +
         format("%.0f", awk_number(field(10))) + " s (" + format("%.0f", static_cast<double>(elapsed_s)) +
         " s so far)";
}

int run_bench(const std::vector<BenchRun>& runs, const SchedulerOptions& o, std::ostream& out, double t0_s) {
  SignalScope signals;
  const int total = static_cast<int>(runs.size());
  std::vector<Active> slots(static_cast<std::size_t>(std::max(1, o.slots)));
  auto say = [&](const std::string& line) { out << line << "\n" << std::flush; };

  auto finish = [&](Active& a, int status) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    const auto drops_after = udp_rcvbuf_errors(o.snmp_path);
    std::error_code ec;
    if (!o.keep_logs) fs::remove(a.dir + "/run.lcmlog", ec);
    const std::string tag = run_tag(a.k, total, a.name);
    // 130: the set was interrupted (Ctrl-C reaches every launcher); the bench says so at the end.
    if (code != 130) {
      if (is_regular_file(a.dir + "/metrics.csv")) {
        const auto elapsed = static_cast<int64_t>(std::floor(runtime::monotonic_s() - t0_s));
        if (auto line = result_line(a.k, total, a.name, read_text(a.dir + "/metrics.csv"), elapsed))
          say(*line);
      } else {
        say(tag + ": FAILED (exit " + std::to_string(code) + "), see " + a.dir + "/launch.log and " + a.dir +
            "/logs/");
      }
      if (auto warning = udp_drop_warning(a.drops_before, drops_after, a.dir, tag)) say(*warning);
    }
    a = Active{};
  };
  auto reap = [&] {
    for (auto& a : slots) {
      if (a.pid <= 0) continue;
      int status = 0;
      const pid_t r = waitpid(a.pid, &status, WNOHANG);
      if (r == a.pid) {
        finish(a, status);
      } else if (r < 0 && errno == ECHILD) {
        a = Active{};
      }
    }
  };
  auto busy = [&] {
    for (const auto& a : slots) {
      if (a.pid > 0) return true;
    }
    return false;
  };
  auto start = [&](int k, const BenchRun& run, int slot) {
    Active a;
    a.k = k;
    a.name = run.name();
    a.dir = o.out_dir + "/runs/" + a.name;
    a.drops_before = udp_rcvbuf_errors(o.snmp_path);
    std::error_code ec;
    fs::remove_all(a.dir, ec);
    if (!ec) fs::create_directories(a.dir, ec);
    const int log =
        ec ? -1 : ::open((a.dir + "/launch.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (log < 0) {
      say(run_tag(k, total, a.name) + ": FAILED (cannot create " + a.dir +
          "/launch.log: " + (ec ? ec.message() : std::strerror(errno)) + ")");
      return;
    }
    std::vector<std::string> args = launch_argv(run, slot, a.dir, o);
    args.insert(args.begin(), o.launcher);
    std::vector<char*> argv;
    for (auto& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    const pid_t pid = fork();
    const int fork_errno = errno;
    if (pid == 0) {
      dup2(log, STDOUT_FILENO);
      dup2(log, STDERR_FILENO);
      const int devnull = ::open("/dev/null", O_RDONLY);
      if (devnull >= 0) dup2(devnull, STDIN_FILENO);
      // As the bash bench's background runs had it: the launcher installs its own SIGINT handler
      // (Ctrl-C from the terminal stops its set cleanly); until then a Ctrl-C does not kill it
      // half-started.
      signal(SIGINT, SIG_IGN);
      signal(SIGQUIT, SIG_IGN);
      signal(SIGCHLD, SIG_DFL);
      execv(argv[0], argv.data());
      dprintf(STDERR_FILENO, "semx: bench: cannot run '%s': %s\n", argv[0], std::strerror(errno));
      _exit(127);
    }
    ::close(log);
    if (pid < 0) {
      say(run_tag(k, total, a.name) + ": FAILED (fork: " + std::strerror(fork_errno) + ")");
      return;
    }
    a.pid = pid;
    slots[static_cast<std::size_t>(slot)] = std::move(a);
  };

  for (int k = 1; k <= total && !SignalScope::interrupted(); ++k) {
    const BenchRun& run = runs[static_cast<std::size_t>(k - 1)];
    // Checked when the run's turn comes, before a slot is free: what an interrupted bench left.
    const std::string dir = o.out_dir + "/runs/" + run.name();
    if (is_regular_file(dir + "/metrics.json")) {
      if (run_finished(dir + "/metrics.json")) {
        say(run_tag(k, total, run.name()) + ": done before, kept");
        continue;
      }
      // A run cut short (Ctrl-C, a killed set) wrote metrics.json too; it is run again, and what
      // it left is kept aside where the report does not read it.
      const std::string aside = set_aside(o.out_dir, run.name());
      say(run_tag(k, total, run.name()) + ": stopped before its end last time, run again (moved to " + aside +
          ")");
    }
    int slot = -1;
    while (true) {
      reap();
      for (std::size_t s = 0; s < slots.size() && slot < 0; ++s) {
        if (slots[s].pid <= 0) slot = static_cast<int>(s);
      }
      if (slot >= 0 || SignalScope::interrupted()) break;
      SignalScope::wait();
    }
    if (SignalScope::interrupted()) break;
    start(k, run, slot);
  }
  // Interrupted or not, the running sets end on their own (a Ctrl-C reached them too) and their
  // folders get their lines.
  while (true) {
    reap();
    if (!busy()) break;
    SignalScope::wait();
  }
  return SignalScope::interrupted() ? 130 : 0;
}

}  // namespace semx::bench
