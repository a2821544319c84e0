#include "semx/runtime/config.hpp"

#include <algorithm>
#include <cerrno>  // program_invocation_short_name
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

namespace semx::runtime {

namespace detail {

template <>
const char* type_name<bool>() {
  return "a boolean (true/false)";
}
template <>
const char* type_name<int>() {
  return "an integer";
}
template <>
const char* type_name<int64_t>() {
  return "an integer";
}
template <>
const char* type_name<uint32_t>() {
  return "a non-negative integer";
}
template <>
const char* type_name<double>() {
  return "a number";
}
template <>
const char* type_name<float>() {
  return "a number";
}
template <>
const char* type_name<std::string>() {
  return "a string";
}
template <>
const char* type_name<std::vector<double>>() {
  return "a list of numbers";
}
template <>
const char* type_name<std::vector<int>>() {
  return "a list of integers";
}
template <>
const char* type_name<std::vector<std::string>>() {
  return "a list of strings";
}

namespace {
template <class T>
bool scalar(const YAML::Node& node, T& out) {
  if (!node.IsScalar()) return false;
  try {
    out = node.as<T>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}
template <class T>
bool floating(const YAML::Node& node, T& out) {
  if (!scalar(node, out)) return false;
  // yaml-cpp accepts .nan and .inf; no parameter of semx is meaningful as either.
  return std::isfinite(out);
}
template <class T>
bool list(const YAML::Node& node, std::vector<T>& out) {
  if (!node.IsSequence()) return false;
  out.clear();
  for (const auto& item : node) {
    T v{};
    if (!convert(item, v)) return false;
    out.push_back(v);
  }
  return true;
}
}  // namespace

template <>
bool convert<bool>(const YAML::Node& n, bool& o) {
  return scalar(n, o);
}
template <>
bool convert<int>(const YAML::Node& n, int& o) {
  return scalar(n, o);
}
template <>
bool convert<int64_t>(const YAML::Node& n, int64_t& o) {
  return scalar(n, o);
}
template <>
bool convert<uint32_t>(const YAML::Node& n, uint32_t& o) {
  int64_t v = 0;
  if (!scalar(n, v) || v < 0 || v > static_cast<int64_t>(UINT32_MAX)) return false;
  o = static_cast<uint32_t>(v);
  return true;
}
template <>
bool convert<double>(const YAML::Node& n, double& o) {
  return floating(n, o);
}
template <>
bool convert<float>(const YAML::Node& n, float& o) {
  return floating(n, o);
}
template <>
bool convert<std::string>(const YAML::Node& n, std::string& o) {
  return scalar(n, o);
}
template <>
bool convert<std::vector<double>>(const YAML::Node& n, std::vector<double>& o) {
  return list(n, o);
}
template <>
bool convert<std::vector<int>>(const YAML::Node& n, std::vector<int>& o) {
  return list(n, o);
}
template <>
bool convert<std::vector<std::string>>(const YAML::Node& n, std::vector<std::string>& o) {
  return list(n, o);
}

}  // namespace detail

ConfigMap::ConfigMap(YAML::Node node, std::string source, std::string path)
    : ConfigMap(std::move(node), std::move(source), std::move(path), std::make_shared<ReadLog>()) {}

ConfigMap::ConfigMap(YAML::Node node, std::string source, std::string path, std::shared_ptr<ReadLog> log)
    : node_(std::move(node)), source_(std::move(source)), path_(std::move(path)), log_(std::move(log)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    throw ConfigError(where() + ": " + (path_.empty() ? std::string("document") : "'" + path_ + "'") +
                      " must be a mapping of key: value");
  }
  log_->keys[path_];  // an opened map is checked by finish() even if nothing was read from it
}

ConfigMap ConfigMap::from_file(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ConfigError(file + ": cannot open config file");
  std::stringstream ss;
  ss << in.rdbuf();
  return from_string(ss.str(), file);
}

ConfigMap ConfigMap::from_string(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
  return ConfigMap(root, source);
}

ConfigMap ConfigMap::empty(const std::string& source) { return ConfigMap(YAML::Node(), source); }

bool ConfigMap::has(const std::string& key) const {
  return node_.IsDefined() && node_.IsMap() && node_[key].IsDefined();
}

std::string ConfigMap::qualified(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

std::string ConfigMap::where(const std::string& key) const {
  YAML::Mark mark = YAML::Mark::null_mark();
  const YAML::Node& node = node_;
  if (!key.empty() && has(key)) {
    mark = node[key].Mark();
  } else if (node.IsDefined()) {
    mark = node_.Mark();
  }
  if (mark.is_null()) return source_;
  return source_ + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

void ConfigMap::fail(const std::string& key, const std::string& what) const {
  throw ConfigError(where(key) + ": '" + qualified(key) + "': " + what);
}

std::optional<YAML::Node> ConfigMap::value(const std::string& key) {
  log_->keys[path_].insert(key);
  if (!has(key)) return std::nullopt;
  const YAML::Node& node = node_;  // const access: operator[] must not insert the key
  YAML::Node v = node[key];
  if (v.IsNull()) fail(key, "has no value");
  return v;
}

void ConfigMap::get_choice(const std::string& key, std::string& out,
                           const std::vector<std::string>& choices) {
  std::string v = out;
  get(key, v);
  for (const auto& c : choices) {
    if (c == v) {
      out = v;
      return;
    }
  }
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  fail(key, "'" + v + "' is not one of: " + list);
}

ConfigMap ConfigMap::child(const std::string& key) {
  const std::optional<YAML::Node> v = value(key);
  if (v && !v->IsMap()) fail(key, "expected a mapping of key: value");
  return ConfigMap(v ? *v : YAML::Node(), source_, qualified(key), log_);
}

std::vector<ConfigMap> ConfigMap::children(const std::string& key) {
  const std::optional<YAML::Node> opt = value(key);
  std::vector<ConfigMap> out;
  if (!opt) return out;
  const YAML::Node v = *opt;
  if (!v.IsSequence()) fail(key, "expected a list");
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = qualified(key) + "[" + std::to_string(i) + "]";
    if (!v[i].IsMap()) {
      YAML::Mark m = v[i].Mark();
      throw ConfigError(source_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) +
                        ": '" + p + "': expected a mapping of key: value");
    }
    out.push_back(ConfigMap(v[i], source_, p, log_));
  }
  return out;
}

void ConfigMap::check_unread(const YAML::Node& node, const std::string& path) const {
  auto it = log_->keys.find(path);
  if (it == log_->keys.end() || !node || !node.IsMap()) return;  // read as a whole value
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (!it->second.count(key)) {
      YAML::Mark m = kv.first.Mark();
      std::string known;
      for (const auto& k : it->second) known += (known.empty() ? "" : ", ") + k;
      throw ConfigError(source_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) +
                        ": unknown key '" + (path.empty() ? key : path + "." + key) + "'" +
                        (known.empty() ? "" : " (known here: " + known + ")"));
    }
    const std::string child_path = path.empty() ? key : path + "." + key;
    if (kv.second.IsMap()) {
      check_unread(kv.second, child_path);
    } else if (kv.second.IsSequence()) {
      for (std::size_t i = 0; i < kv.second.size(); ++i) {
        check_unread(kv.second[i], child_path + "[" + std::to_string(i) + "]");
      }
    }
  }
}

void ConfigMap::finish() const { check_unread(node_, path_); }

void ConfigMap::set_overridden(std::set<std::string> keys, std::string file) {
  log_->overridden = std::move(keys);
  log_->file = std::move(file);
}

void ConfigMap::note(const std::string& key, const std::string& value, bool present) {
  const std::string k = qualified(key);
  std::string origin = "default";
  if (present) origin = log_->overridden.count(k) ? "--set" : (log_->file.empty() ? source_ : log_->file);
  log_->values.push_back({k, value, origin});
}

namespace {

std::vector<EffectiveValue>& registry() {
  static std::vector<EffectiveValue> values;
  return values;
}

std::string override_key(const std::string& assignment) { return assignment.substr(0, assignment.find('=')); }

// The value at a dotted path of `root`, if there is one.
std::optional<YAML::Node> at_path(const YAML::Node& root, const std::string& key) {
  YAML::Node n;
  n.reset(root);  // reset() rebinds the handle; assignment would write into the document
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) {
    const YAML::Node& c = n;  // const access: operator[] must not insert the key
    if (!c || !c.IsMap() || !c[part]) return std::nullopt;
    n.reset(c[part]);
  }
  return n;
}

}  // namespace

const std::vector<EffectiveValue>& effective_config() { return registry(); }

std::string effective_config_yaml(const std::vector<EffectiveValue>& values) {
  std::ostringstream o;
  o << "# Effective configuration (key: value  # origin: default, the YAML file, or --set/a flag)\n";
  std::size_t width = 0;
  for (const auto& v : values) width = std::max(width, v.key.size() + v.value.size() + 2);
  for (const auto& v : values) {
    const std::string line = v.key + ": " + v.value;
    o << line << std::string(width + 2 - line.size(), ' ') << "# " << v.origin << "\n";
  }
  return o.str();
}

namespace detail {

ConfigMap with_overrides(ConfigMap map, const std::string& file, const std::vector<std::string>& overrides) {
  if (overrides.empty()) {
    map.set_overridden({}, file);
    return map;
  }
  YAML::Node root = YAML::Clone(map.node());
  if (!root || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  std::set<std::string> keys;
  for (const auto& o : overrides) {
    const std::string key = override_key(o);
    if (!file.empty()) {
      if (auto before = at_path(map.node(), key)) {
        YAML::Emitter e;
        e << YAML::Flow << *before;
        const std::string now = o.substr(std::min(o.size(), key.size() + 1));
        if (e.c_str() != now) {
          std::cerr << program_invocation_short_name << ": note: --set " << o << " replaces " << key << ": "
                    << e.c_str() << " from " << file << ":" << before->Mark().line + 1 << std::endl;
        }
      }
    }
    apply_override(root, o);
    keys.insert(key);
  }
  ConfigMap merged(root, file.empty() ? std::string("--set") : file + " + --set");
  merged.set_overridden(std::move(keys), file);
  return merged;
}

void record_effective(const std::vector<EffectiveValue>& values) {
  auto& all = registry();
  all.insert(all.end(), values.begin(), values.end());
  const char* out = std::getenv(kEffectiveConfigEnv);
  if (!out || !*out) return;
  std::ofstream f(out);
  f << "# " << program_invocation_short_name << "\n" << effective_config_yaml(all);
  if (!f) std::cerr << program_invocation_short_name << ": cannot write the effective configuration to " << out << std::endl;
}

}  // namespace detail

void apply_override(YAML::Node& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ConfigError("--set '" + assignment + "': expected key=value (e.g. --set planner.samples=45)");
  }
  const std::string key = assignment.substr(0, eq);
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw ConfigError("--set '" + assignment + "': cannot parse value: " + e.msg);
  }
  // Walk by dotted path, creating maps as needed. yaml-cpp nodes are handles, so reassigning
  // a local would rebind it; collect the chain instead.
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) {
    if (part.empty()) throw ConfigError("--set '" + assignment + "': empty key component");
    parts.push_back(part);
  }
  std::vector<YAML::Node> chain{root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = chain.back()[parts[i]];
    if (next && !next.IsMap() && !next.IsNull()) {
      throw ConfigError("--set '" + assignment + "': '" + parts[i] + "' is not a mapping");
    }
    if (!next || next.IsNull()) {
      chain.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
      next = chain.back()[parts[i]];
    }
    chain.push_back(next);
  }
  chain.back()[parts.back()] = value;
}

}  // namespace semx::runtime
