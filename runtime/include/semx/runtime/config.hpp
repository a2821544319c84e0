// Typed YAML configuration with errors that name the file, line and key.
//
// A module's config is a plain struct with defaults; a `load(ConfigMap&)` function reads the
// keys it knows. Reading is strict: a key the struct does not read, a value of the wrong type
// or a value outside its range is an error, because a silently ignored typo in a benchmark
// config produces wrong figures that look right.
//
//   struct MapperConfig { double resolution = 0.1; int max_range_px = 5; };
//   void load(semx::runtime::ConfigMap& m, MapperConfig& c) {
//     m.get("resolution", c.resolution, 0.01, 1.0);
//     m.get("max_range_px", c.max_range_px);
//   }
//   auto cfg = semx::runtime::load_config_file<MapperConfig>("mapper.yaml");
#pragma once

#include <yaml-cpp/yaml.h>

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace semx::runtime {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The configuration a process runs with, as `rosparam dump` would show it: every key a module
// read, its value, and where the value came from: "default", the YAML file, or "--set" (a flag,
// including the shorthands such as the planner's --samples, which are --set underneath).
struct EffectiveValue {
  std::string key;     // dotted path
  std::string value;   // YAML text
  std::string origin;  // "default", the file's path, or "--set"
};

// A view of one YAML mapping. Keys are recorded as they are read so finish() can report the
// ones nobody asked for.
class ConfigMap {
 public:
  // `source` names where the node came from (a file path, "--set", ...) for error messages.
  ConfigMap(YAML::Node node, std::string source, std::string path = "");

  static ConfigMap from_file(const std::string& file);
  static ConfigMap from_string(const std::string& text, const std::string& source);
  static ConfigMap empty(const std::string& source = "<defaults>");

  bool has(const std::string& key) const;

  // Reads `key` into `out` if present; leaves the default otherwise.
  template <class T>
  void get(const std::string& key, T& out);
  // As get(), and rejects values outside [lo, hi].
  template <class T>
  void get(const std::string& key, T& out, T lo, T hi);
  // As get(), for a string that must be one of `choices`.
  void get_choice(const std::string& key, std::string& out, const std::vector<std::string>& choices);

  // A nested mapping; an absent key gives an empty map (all defaults).
  ConfigMap child(const std::string& key);
  // A nested sequence of mappings (e.g. a list of processes).
  std::vector<ConfigMap> children(const std::string& key);

  // Throws if any key anywhere in the document (this map, and every child or list entry opened
  // from it) was never read. Call it once, on the root, after the whole struct is loaded.
  void finish() const;

  // Every value read so far anywhere in the document, with its origin (effective_config()).
  const std::vector<EffectiveValue>& effective() const { return log_->values; }
  // Keys (dotted) whose values came from --set rather than from source(): load_config's.
  void set_overridden(std::set<std::string> keys, std::string file);

  // "file:line:col" of `key`, or of this map when key is empty.
  std::string where(const std::string& key = "") const;
  const std::string& source() const { return source_; }
  const YAML::Node& node() const { return node_; }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  std::string qualified(const std::string& key) const;
  // The value of `key` (marking it read), or nullopt when absent.
  std::optional<YAML::Node> value(const std::string& key);

  struct ReadLog {
    std::map<std::string, std::set<std::string>> keys;  // map path -> keys read there
    std::vector<EffectiveValue> values;                 // in the order read
    std::set<std::string> overridden;                   // dotted keys set by --set
    std::string file;                                   // the YAML file, "" for none
  };
  void note(const std::string& key, const std::string& value, bool present);
  ConfigMap(YAML::Node node, std::string source, std::string path, std::shared_ptr<ReadLog> log);
  void check_unread(const YAML::Node& node, const std::string& path) const;

  YAML::Node node_;
  std::string source_;
  std::string path_;  // dotted key path of this map inside the document, "" at the root
  std::shared_ptr<ReadLog> log_;
};

// Applies "a.b.c=value" overrides (from --set flags) onto a YAML document before it is read.
void apply_override(YAML::Node& root, const std::string& assignment);

// Every value load_config() read in this process so far (each call appends its struct's).
const std::vector<EffectiveValue>& effective_config();
// The effective configuration as YAML with the origin of each value as a comment.
std::string effective_config_yaml(const std::vector<EffectiveValue>& values);
// Where load_config() writes effective_config_yaml() after each call: $SEMX_CONFIG_OUT (the
// launcher sets it to LOG_DIR/NAME.config.yaml, so a run folder holds every process's), or
// nowhere when unset.
inline constexpr const char* kEffectiveConfigEnv = "SEMX_CONFIG_OUT";

// Loads a config struct from a file (or defaults when `file` is empty) plus overrides.
// `load` must be findable by ADL: void load(ConfigMap&, T&).
template <class T>
T load_config(const std::string& file, const std::vector<std::string>& overrides = {});

// ---- implementation of the templates ----

namespace detail {
// A value as one line of YAML (flow style, doubles to 15 digits: 0.1, not 0.10000000000000001).
template <class T>
std::string yaml_text(const T& value) {
  YAML::Emitter e;
  e.SetDoublePrecision(15);
  e.SetFloatPrecision(7);
  e << YAML::Flow << value;
  return e.c_str();
}
template <class T>
const char* type_name();
template <class T>
bool convert(const YAML::Node& node, T& out);
}  // namespace detail

template <class T>
void ConfigMap::get(const std::string& key, T& out) {
  const std::optional<YAML::Node> v = value(key);
  if (!v) {
    note(key, detail::yaml_text(out), false);
    return;
  }
  T parsed{};
  if (!detail::convert(*v, parsed)) {
    fail(key, std::string("expected ") + detail::type_name<T>());
  }
  out = parsed;
  note(key, detail::yaml_text(*v), true);
}

template <class T>
void ConfigMap::get(const std::string& key, T& out, T lo, T hi) {
  T parsed = out;
  get(key, parsed);
  if (!(parsed >= lo && parsed <= hi)) {
    fail(key, "value " + YAML::Dump(YAML::Node(parsed)) + " is outside [" + YAML::Dump(YAML::Node(lo)) +
                  ", " + YAML::Dump(YAML::Node(hi)) + "]");
  }
  out = parsed;
}

namespace detail {
// Applies the overrides to `map`'s document (saying on stderr when one replaces a value the file
// set: a flag silently beating the YAML was a trap) and records which keys they set.
ConfigMap with_overrides(ConfigMap map, const std::string& file, const std::vector<std::string>& overrides);
void record_effective(const std::vector<EffectiveValue>& values);
}  // namespace detail

template <class T>
T load_config(const std::string& file, const std::vector<std::string>& overrides) {
  ConfigMap map = detail::with_overrides(file.empty() ? ConfigMap::empty() : ConfigMap::from_file(file), file,
                                         overrides);
  T cfg{};
  load(map, cfg);
  map.finish();
  detail::record_effective(map.effective());
  return cfg;
}

}  // namespace semx::runtime
