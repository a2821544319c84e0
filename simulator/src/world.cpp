#include "semx/simulator/world.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "semx/simulator/collision.hpp"

namespace semx::simulator {
namespace {

using runtime::ConfigMap;

constexpr double kDeg = M_PI / 180.0;
// Solids may poke out of the bounds by rounding only.
constexpr double kBoundsTol = 1e-6;

Eigen::Vector3d get_vec3(ConfigMap& m, const std::string& key, bool required) {
  if (!m.has(key)) {
    if (required) m.fail(key, "is required");
    return Eigen::Vector3d::Zero();
  }
  std::vector<double> v;
  m.get(key, v);
  if (v.size() != 3) m.fail(key, "expected a list of 3 numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

double get_required(ConfigMap& m, const std::string& key) {
  if (!m.has(key)) m.fail(key, "is required");
  double v = 0;
  m.get(key, v);
  return v;
}

std::string num(double v) {
  if (v == 0) v = 0;  // no "-0"
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string vec(const Eigen::Vector3d& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

// Short form for messages (the file writer needs the exact round-trip form instead).
std::string msg_vec(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.4g, %.4g, %.4g]", v.x(), v.y(), v.z());
  return buf;
}

// Why these bounds are more than a world may hold (world.hpp), or "".
std::string bounds_too_large(const Aabb& b) {
  if (!b.min.allFinite() || !b.max.allFinite()) return "must be finite";
  const Eigen::Vector3d e = b.max - b.min;
  if (e.maxCoeff() > kMaxWorldExtent)
    return "span " + msg_vec(e) + " m: at most " + num(kMaxWorldExtent) + " m on each axis";
  if (e.prod() > kMaxWorldVolume)
    return "hold " + num(e.prod()) + " m³: at most " + num(kMaxWorldVolume) + " m³";
  return "";
}

using WhereFn = std::function<std::string(size_t)>;

// Checks shared by the parser and validate_world; `where_solid` / `where_start` locate the
// offending input in the message.
void check_and_assign(World& w, const WhereFn& where_solid, const std::string& where_start) {
  std::map<uint16_t, SemanticClass> instance_class;
  std::map<uint16_t, size_t> instance_first;
  for (size_t i = 0; i < w.solids.size(); ++i) {
    const Solid& s = w.solids[i];
    if (!w.bounds.contains(s.bounds(), kBoundsTol)) {
      const Aabb b = s.bounds();
      std::ostringstream os;
      os << where_solid(i) << ": solid " << i << " (" << runtime::class_info(s.cls).name
         << ") is outside the world bounds: it spans " << msg_vec(b.min) << " .. " << msg_vec(b.max)
         << ", bounds are " << msg_vec(w.bounds.min) << " .. " << msg_vec(w.bounds.max);
      throw WorldError(os.str());
    }
    if (s.instance == 0) continue;
    auto [it, fresh] = instance_class.emplace(s.instance, s.cls);
    if (fresh) {
      instance_first[s.instance] = i;
    } else if (it->second != s.cls) {
      throw WorldError(where_solid(i) + ": instance " + std::to_string(s.instance) + " is a " +
                       std::string(runtime::class_info(s.cls).name) + " here but a " +
                       std::string(runtime::class_info(it->second).name) + " at " +
                       where_solid(instance_first[s.instance]) +
                       " (solids may share an instance only within one class)");
    }
  }
  uint16_t next = 1;
  for (auto& s : w.solids) {
    if (s.instance != 0) continue;
    while (instance_class.count(next)) ++next;
    if (next == 0) throw WorldError(where_start + ": more than 65535 instances");
    s.instance = next;
    instance_class.emplace(next, s.cls);
  }
  if (!w.bounds.contains(w.start.position)) {
    std::ostringstream os;
    os << where_start << ": start position " << msg_vec(w.start.position) << " is outside the world bounds";
    throw WorldError(os.str());
  }
  const int hit = first_solid_hit_by_body(w, w.start.position, w.start.yaw);
  if (hit >= 0) {
    std::ostringstream os;
    os << where_start << ": the vehicle body (" << num(kVehicleSize.x()) << " x " << num(kVehicleSize.y())
       << " x " << num(kVehicleSize.z()) << " m) at the start pose " << msg_vec(w.start.position)
       << " intersects solid " << hit << " (" << runtime::class_info(w.solids[hit].cls).name
       << ") defined at " << where_solid(hit);
    throw WorldError(os.str());
  }
}

Solid read_solid(ConfigMap& m) {
  Solid s;
  std::string type = "box";
  if (!m.has("type")) m.fail("type", "is required (box or cylinder)");
  m.get_choice("type", type, {"box", "cylinder"});
  s.shape = type == "box" ? Shape::kBox : Shape::kCylinder;

  if (!m.has("class")) m.fail("class", "is required");
  std::string cls_name;
  m.get("class", cls_name);
  const auto cls = runtime::class_from_name(cls_name);
  if (!cls || *cls == SemanticClass::kNone) {
    std::string names;
    for (const auto& info : runtime::kSemanticClasses) {
      if (info.id != SemanticClass::kNone) names += (names.empty() ? "" : ", ") + std::string(info.name);
    }
    m.fail("class", "unknown class '" + cls_name + "' (known: " + names + ")");
  }
  s.cls = *cls;
  s.color = class_color(s.cls);
  s.center = get_vec3(m, "center", true);

  if (s.shape == Shape::kBox) {
    s.size = get_vec3(m, "size", true);
    if ((s.size.array() <= 0).any()) m.fail("size", "every extent must be positive");
    double yaw_deg = 0;
    m.get("yaw_deg", yaw_deg);
    s.yaw = yaw_deg * kDeg;
  } else {
    const double r = get_required(m, "radius");
    if (r <= 0) m.fail("radius", "must be positive");
    const double h = get_required(m, "height");
    if (h <= 0) m.fail("height", "must be positive");
    s.size = {2 * r, 2 * r, h};
  }
  if (m.has("instance")) {
    int instance = 0;
    m.get("instance", instance, 1, 65535);
    s.instance = static_cast<uint16_t>(instance);
  }
  if (m.has("color")) {
    std::vector<int> c;
    m.get("color", c);
    if (c.size() != 3 || c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] > 255 || c[1] > 255 || c[2] > 255) {
      m.fail("color", "expected [r, g, b] with each in 0..255");
    }
    s.color = {static_cast<uint8_t>(c[0]), static_cast<uint8_t>(c[1]), static_cast<uint8_t>(c[2])};
  }
  return s;
}

}  // namespace

int World::object_count() const {
  std::set<uint16_t> ids;
  for (const auto& s : solids) {
    if (!runtime::class_info(s.cls).structural) ids.insert(s.instance);
  }
  return static_cast<int>(ids.size());
}

uint16_t World::max_instance() const {
  uint16_t m = 0;
  for (const auto& s : solids) m = std::max(m, s.instance);
  return m;
}

World parse_world(const std::string& text, const std::string& source) {
  ConfigMap root = ConfigMap::from_string(text, source);
  World w;
  w.source = source;
  if (!root.node() || root.node().IsNull()) throw WorldError(source + ": empty world file");
  root.get("name", w.name);

  if (!root.has("bounds")) root.fail("bounds", "is required");
  ConfigMap bounds = root.child("bounds");
  w.bounds.min = get_vec3(bounds, "min", true);
  w.bounds.max = get_vec3(bounds, "max", true);
  if ((w.bounds.max.array() <= w.bounds.min.array()).any())
    bounds.fail("max", "must exceed min on every axis");
  if (const std::string why = bounds_too_large(w.bounds); !why.empty()) bounds.fail("max", why);

  if (!root.has("start")) root.fail("start", "is required");
  ConfigMap start = root.child("start");
  w.start.position = get_vec3(start, "position", true);
  double yaw_deg = 0;
  start.get("yaw_deg", yaw_deg);
  w.start.yaw = yaw_deg * kDeg;

  if (!root.has("solids")) root.fail("solids", "is required");
  std::vector<ConfigMap> maps = root.children("solids");
  if (maps.empty()) root.fail("solids", "a world needs at least one solid");
  if (maps.size() > kMaxWorldSolids)
    root.fail("solids", std::to_string(maps.size()) + " solids, at most " + std::to_string(kMaxWorldSolids));
  for (auto& m : maps) w.solids.push_back(read_solid(m));
  root.finish();

  check_and_assign(
      w, [&](size_t i) { return maps[i].where(); }, start.where());
  return w;
}

World load_world(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw WorldError(file + ": cannot open world file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_world(ss.str(), file);
}

void validate_world(World& world) {
  const std::string src = world.source.empty() ? std::string("<world ") + world.name + ">" : world.source;
  for (size_t i = 0; i < world.solids.size(); ++i) {
    const Solid& s = world.solids[i];
    const std::string where = src + ": solid " + std::to_string(i);
    if (s.cls == SemanticClass::kNone || static_cast<int>(s.cls) >= static_cast<int>(SemanticClass::kCount)) {
      throw WorldError(where + ": invalid class");
    }
    if ((s.size.array() <= 0).any() || !s.size.allFinite() || !s.center.allFinite() ||
        !std::isfinite(s.yaw)) {
      throw WorldError(where + ": size must be positive and finite");
    }
  }
  if ((world.bounds.max.array() <= world.bounds.min.array()).any()) throw WorldError(src + ": empty bounds");
  if (const std::string why = bounds_too_large(world.bounds); !why.empty()) throw WorldError(src + ": bounds " + why);
  if (world.solids.size() > kMaxWorldSolids)
    throw WorldError(src + ": " + std::to_string(world.solids.size()) + " solids, at most " +
                     std::to_string(kMaxWorldSolids));
  check_and_assign(
      world, [&](size_t i) { return src + ": solid " + std::to_string(i); }, src + ": start");
}

std::string world_to_yaml(const World& w) {
  std::ostringstream os;
  os << "# semx world (format: docs/worlds.md)\n";
  if (!w.name.empty()) os << "name: " << w.name << "\n";
  os << "bounds: {min: " << vec(w.bounds.min) << ", max: " << vec(w.bounds.max) << "}\n";
  os << "start: {position: " << vec(w.start.position) << ", yaw_deg: " << num(w.start.yaw / kDeg) << "}\n";
  os << "solids:\n";
  for (const auto& s : w.solids) {
    os << "  - {type: " << (s.shape == Shape::kBox ? "box" : "cylinder")
       << ", class: " << runtime::class_info(s.cls).name << ", instance: " << s.instance
       << ", center: " << vec(s.center);
    if (s.shape == Shape::kBox) {
      os << ", size: " << vec(s.size);
      if (s.yaw != 0) os << ", yaw_deg: " << num(s.yaw / kDeg);
    } else {
      os << ", radius: " << num(s.radius()) << ", height: " << num(s.size.z());
    }
    if (s.color != class_color(s.cls)) {
      os << ", color: [" << int(s.color.r) << ", " << int(s.color.g) << ", " << int(s.color.b) << "]";
    }
    os << "}\n";
  }
  return os.str();
}

void save_world(const World& world, const std::string& file) {
  std::ofstream out(file);
  if (!out) throw WorldError(file + ": cannot write world file");
  out << world_to_yaml(world);
  if (!out) throw WorldError(file + ": write failed");
}

int first_solid_hit_by_body(const World& world, const Eigen::Vector3d& position, double yaw,
                            const Eigen::Vector3d& body_size) {
  const YawBox body{position, body_size, yaw};
  for (size_t i = 0; i < world.solids.size(); ++i) {
    if (overlaps(body, world.solids[i])) return static_cast<int>(i);
  }
  return -1;
}

std::string shipped_world_path(const std::string& name) {
  if (name.find('/') != std::string::npos ||
      (name.size() > 5 && name.compare(name.size() - 5, 5, ".yaml") == 0)) {
    return name;
  }
  return std::string(SEMX_WORLDS_DIR) + "/" + name + ".yaml";
}

}  // namespace semx::simulator
