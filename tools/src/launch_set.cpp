#include "semx/tools/launch_set.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "semx/runtime/config.hpp"

namespace semx::tools {

using semx::runtime::ConfigError;
using semx::runtime::ConfigMap;

std::string substitute(const std::string& text, const std::map<std::string, std::string>& vars) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text.compare(i, 2, "${") == 0) {
      const std::size_t end = text.find('}', i + 2);
      if (end == std::string::npos) throw std::runtime_error("unterminated ${ in '" + text + "'");
      const std::string name = text.substr(i + 2, end - i - 2);
      auto it = vars.find(name);
      if (it != vars.end()) {
        out += it->second;
      } else if (const char* env = std::getenv(name.c_str())) {
        out += env;
      } else {
        throw std::runtime_error("unknown variable ${" + name + "}");
      }
      i = end + 1;
    } else {
      out += text[i++];
    }
  }
  return out;
}

LaunchSet load_launch_set(const std::string& file, const std::map<std::string, std::string>& overrides,
                          const std::map<std::string, std::string>& builtins) {
  ConfigMap root = ConfigMap::from_file(file);
  LaunchSet set;
  set.file = file;
  root.get("name", set.name);
  root.get("description", set.description);
  if (set.name.empty()) root.fail("name", "a set needs a name");

  ConfigMap args = root.child("args");
  if (args.node().IsMap()) {
    for (const auto& kv : args.node()) {
      const std::string key = kv.first.as<std::string>();
      std::string value;
      args.get(key, value);
      set.args[key] = value;
    }
  }
  for (const auto& [key, value] : overrides) {
    if (!set.args.count(key)) {
      std::string known;
      for (const auto& a : set.args) known += (known.empty() ? "" : ", ") + a.first;
      throw ConfigError(file + ": --arg " + key + ": the set has no such arg" +
                        (known.empty() ? std::string(" (it takes none)") : " (it takes: " + known + ")"));
    }
    set.args[key] = value;
  }
  std::map<std::string, std::string> vars = builtins;
  for (const auto& [k, v] : set.args) vars[k] = v;

  root.get("log_dir", set.log_dir);
  try {
    set.log_dir = substitute(set.log_dir, vars);
  } catch (const std::exception& e) {
    root.fail("log_dir", e.what());
  }

  std::vector<std::string> dirs;
  root.get("dirs", dirs);
  for (const auto& d : dirs) {
    try {
      const std::string dir = substitute(d, vars);
      if (!dir.empty()) set.dirs.push_back(dir);
    } catch (const std::exception& e) {
      root.fail("dirs", e.what());
    }
  }

  for (ConfigMap& p : root.children("processes")) {
    ProcessSpec spec;
    p.get("name", spec.name);
    if (spec.name.empty()) p.fail("name", "every process needs a name");
    for (const auto& other : set.processes) {
      if (other.name == spec.name) p.fail("name", "process '" + spec.name + "' is defined twice");
    }
    std::vector<std::string> command;
    p.get("command", command);
    if (command.empty()) p.fail("command", "needs a non-empty list: [program, arg, ...]");
    for (const auto& word : command) {
      try {
        const std::string w = substitute(word, vars);
        // An arg that substitutes to nothing drops out, so optional flags can be left empty.
        if (!w.empty()) spec.command.push_back(w);
      } catch (const std::exception& e) {
        p.fail("command", e.what());
      }
    }
    if (spec.command.empty()) p.fail("command", "is empty after substitution");
    std::string restart = "never";
    p.get_choice("restart", restart, {"never", "on-failure", "always"});
    spec.restart = restart == "always"       ? RestartPolicy::kAlways
                   : restart == "on-failure" ? RestartPolicy::kOnFailure
                                             : RestartPolicy::kNever;
    p.get("max_restarts", spec.max_restarts, 0, 1000);
    p.get("restart_delay", spec.restart_delay_s, 0.0, 600.0);
    spec.restart_delay_max_s = std::max(spec.restart_delay_max_s, spec.restart_delay_s);
    p.get("restart_delay_max", spec.restart_delay_max_s, spec.restart_delay_s, 3600.0);
    p.get("required", spec.required);
    p.get("ends_set", spec.ends_set);
    p.get("start_delay", spec.start_delay_s, 0.0, 600.0);
    p.get("show", spec.show);
    ConfigMap env = p.child("env");
    if (env.node().IsMap()) {
      for (const auto& kv : env.node()) {
        const std::string key = kv.first.as<std::string>();
        std::string value;
        env.get(key, value);
        try {
          spec.env[key] = substitute(value, vars);
        } catch (const std::exception& e) {
          env.fail(key, e.what());
        }
      }
    }
    set.processes.push_back(std::move(spec));
  }
  if (set.processes.empty()) root.fail("processes", "a set needs at least one process");
  root.finish();
  return set;
}

ExitAction on_process_exit(const ProcessSpec& spec, int exit_code, int restarts, bool stopping) {
  if (stopping) return ExitAction::kContinue;
  const bool failed = exit_code != 0;
  const bool may_restart = restarts < spec.max_restarts;
  if (spec.restart == RestartPolicy::kAlways && may_restart) return ExitAction::kRestart;
  if (spec.restart == RestartPolicy::kOnFailure && failed && may_restart) return ExitAction::kRestart;
  if (failed) return spec.required ? ExitAction::kFailSet : ExitAction::kContinue;
  return spec.ends_set ? ExitAction::kEndSet : ExitAction::kContinue;
}

double restart_delay(const ProcessSpec& spec, int in_a_row) {
  double d = spec.restart_delay_s;
  for (int i = 1; i < in_a_row && d < spec.restart_delay_max_s; ++i) d *= 2;
  return std::min(d, spec.restart_delay_max_s);
}

}  // namespace semx::tools
