// semx-launch: starts a process set (tools/launch/*.yaml) and supervises it. See docs/launch.md.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "semx/runtime/args.hpp"
#include "semx/runtime/executable_dir.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/message_auth.hpp"
#include "semx/tools/bus_claim.hpp"
#include "semx/tools/launch_set.hpp"
#include "semx/tools/supervisor.hpp"

using namespace semx::runtime;
using namespace semx::tools;
namespace fs = std::filesystem;

namespace {

std::string source_root() {
  if (const char* env = std::getenv("SEMX_ROOT")) return env;
  return SEMX_SOURCE_DIR;
}

// Where `./semx view`, `monitor`, `record` and `spy` find the live sets of this user: a file per
// set with its URL and key, readable by this user only, removed when the set ends.
class LiveSetFile {
 public:
  LiveSetFile(const std::string& set, const std::string& url, const AuthKey& key) {
    const char* dir_env = std::getenv("SEMX_LIVE_DIR");
    const std::string dir = dir_env && *dir_env ? dir_env : "/tmp/semx-live-" + std::to_string(getuid());
    std::error_code ec;
    fs::create_directories(dir, ec);
    fs::permissions(dir, fs::perms::owner_all, ec);
    path_ = dir + "/" + set + "-" + std::to_string(getpid()) + ".env";
    fs::remove(path_, ec);
    const std::string text = "SEMX_SET=" + set + "\nSEMX_SET_PID=" + std::to_string(getpid()) +
                             "\nLCM_DEFAULT_URL='" + url + "'\nSEMX_AUTH_KEY=" + key.hex() + "\n";
    const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0 || ::write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size())) path_.clear();
    if (fd >= 0) ::close(fd);
  }
  ~LiveSetFile() {
    std::error_code ec;
    if (!path_.empty()) fs::remove(path_, ec);
  }

 private:
  std::string path_;
};

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-launch", [&] {
    std::string set_name, lcm_url, log_dir, auth_key, key_out, port_policy = "move";
    std::vector<std::string> arg_list, without;
    double duration = 0, grace = 5;
    bool list = false, no_color = false;
    ArgParser p(
        "semx-launch",
        "Starts a process set and supervises it: output prefixed by process name, restarts as the set\n"
        "says, Ctrl-C stops everything. SET is a file or a name in tools/launch/ (without .yaml).");
    p.positional("SET", "the process set", &set_name)
        .repeated("arg", "NAME=VALUE", "set one of the set's args (see --list)", &arg_list)
        .repeated("without", "NAME", "do not start process NAME (one the set marks required: false)",
                  &without)
        .option("lcm-url", "URL", "LCM provider for every process (exported as LCM_DEFAULT_URL)", &lcm_url)
        .option("port-policy", "P",
                "when another set or program talks on the URL's port: move (default: take the next free "
                "port and say so; a multi-host URL, ttl > 0, refuses instead), refuse, or share (sessions "
                "still keep the sets apart)",
                &port_policy)
        .option("auth-key", "FILE",
                "the set's key (64 hex digits), shared by the hosts of a multi-host set; default: a new "
                "random key for this set",
                &auth_key)
        .option("key-out", "FILE", "write the set's key to FILE (mode 0600; an existing file is refused)",
                &key_out)
        .option("duration", "S", "stop the set after S wall seconds", &duration)
        .option("grace", "S", "seconds between SIGINT and SIGKILL when stopping (default 5)", &grace)
        .option("log-dir", "DIR",
                "write each process's output to DIR/NAME.log too (overrides the set's log_dir)", &log_dir)
        .flag("list", "print the set's args and processes and exit", &list)
        .flag("no-color", "do not colour process names", &no_color);
    if (!p.parse(argc, argv)) return 0;

    const std::string root = source_root();
    std::string file = set_name;
    if (!fs::exists(file)) file = root + "/tools/launch/" + set_name + ".yaml";
    if (!fs::exists(file)) {
      std::string known;
      if (fs::is_directory(root + "/tools/launch")) {
        for (const auto& e : fs::directory_iterator(root + "/tools/launch")) {
          if (e.path().extension() == ".yaml") known += " " + e.path().stem().string();
        }
      }
      throw ArgError("no process set '" + set_name + "' (a file, or one of:" + known + ")");
    }
    std::map<std::string, std::string> overrides;
    for (const auto& a : arg_list) {
      const auto eq = a.find('=');
      if (eq == std::string::npos || eq == 0) throw ArgError("--arg '" + a + "': expected NAME=VALUE");
      overrides[a.substr(0, eq)] = a.substr(eq + 1);
    }
    SupervisorOptions o;
    o.bin_dir = executable_dir();
    o.root_dir = root;
    // Always exported: a child that is not a semx process (lcm-logger) would otherwise take LCM's
    // own default, whose ~200 KB receive buffer dropped half of the depth images and nearly every
    // ESDF_LOCAL of an env3 log (and some MAP_UPDATEs and SIM_CLOCKs of every demo log).
    o.lcm_url = semx::runtime::resolve_lcm_url(lcm_url);
    BusClaimOptions bus;
    if (port_policy == "move") {
      bus.policy = PortPolicy::kMove;
    } else if (port_policy == "refuse") {
      bus.policy = PortPolicy::kRefuse;
    } else if (port_policy == "share") {
      bus.policy = PortPolicy::kShare;
    } else {
      throw ArgError("--port-policy '" + port_policy + "': expected move, refuse or share");
    }
    // Every message the set sends is signed with this key; processes without it are not heard.
    const AuthKey key = [&] {
      try {
        return auth_key.empty() ? AuthKey::random() : AuthKey::from_file(auth_key);
      } catch (const std::exception& e) {
        throw ArgError(std::string("--auth-key: ") + e.what());
      }
    }();
    o.duration_s = duration;
    o.grace_s = grace;
    o.log_dir = log_dir;
    o.color = !no_color && isatty(STDOUT_FILENO);
    LaunchSet set = load_launch_set(file, overrides, {{"root", root}, {"bin", o.bin_dir}});
    for (const std::string& name : without) {
      const auto it = std::find_if(set.processes.begin(), set.processes.end(),
                                   [&](const ProcessSpec& proc) { return proc.name == name; });
      if (it == set.processes.end()) throw ArgError("--without '" + name + "': the set has no such process");
      if (it->required) throw ArgError("--without '" + name + "': the set needs it (required)");
      set.processes.erase(it);
    }
    if (list) {
      std::cout << set.name << ": " << set.description << "\nargs:\n";
      for (const auto& [k, v] : set.args) std::cout << "  " << k << " = " << v << "\n";
      std::cout << "processes:\n";
      for (const auto& proc : set.processes) {
        std::cout << "  " << proc.name << ":";
        for (const auto& w : proc.command) std::cout << " " << w;
        std::cout << "\n";
      }
      return 0;
    }
    BusClaim claim;
    try {
      claim = claim_bus(o.lcm_url, bus);
    } catch (const std::exception& e) {
      std::cerr << "semx-launch: " << o.lcm_url << ": " << e.what() << "\n";
      return 1;
    }
    if (!claim.why_moved.empty()) {
      std::cout << "[semx-launch] " << claim.why_moved << ": this set uses " << claim.url << std::endl;
    } else if (!claim.shared.empty()) {
      std::cout << "[semx-launch] warning: " << claim.shared << "; this set shares it (its session keeps it apart)"
                << std::endl;
    }
    o.lcm_url = claim.url;
    if (!key_out.empty()) {
      try {
        key.write_file(key_out);
      } catch (const std::exception& e) {
        throw ArgError(std::string("--key-out: ") + e.what());
      }
    }
    setenv("SEMX_AUTH_KEY", key.hex().c_str(), 1);
    unsetenv("SEMX_AUTH_KEY_FILE");
    const LiveSetFile live(set.name, o.lcm_url, key);
    return run_launch_set(set, o);
  });
}
