#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world.hpp"
#include "test_util.hpp"

namespace semx::simulator {
namespace {

const char* kGood = R"(name: tiny
bounds: {min: [-0.2, -0.2, -0.1], max: [4.2, 3.2, 2.8]}
start: {position: [1, 1, 1.2], yaw_deg: 90}
solids:
  - {type: box, class: floor, center: [2, 1.5, -0.05], size: [4.4, 3.4, 0.1]}
  - {type: box, class: wall, center: [2, -0.1, 1.35], size: [4.4, 0.2, 2.7], color: [10, 20, 30]}
  - {type: box, class: table, center: [3, 2, 0.375], size: [1.2, 0.8, 0.75], yaw_deg: 30, instance: 7}
  - {type: cylinder, class: plant, center: [3.5, 0.5, 0.5], radius: 0.2, height: 1.0}
  - {type: box, class: table, center: [3, 2, 0.8], size: [0.3, 0.3, 0.1], instance: 7}
)";

// Replaces the first occurrence of `from` in kGood.
std::string bad(const std::string& from, const std::string& to) {
  std::string s = kGood;
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  s.replace(p, from.size(), to);
  return s;
}

// Parses and returns the error message ("" if it parsed).
std::string error_of(const std::string& text) {
  try {
    parse_world(text, "w.yaml");
  } catch (const WorldError& e) {
    return e.what();
  }
  return "";
}

TEST(WorldParse, GoodFile) {
  const World w = parse_world(kGood, "w.yaml");
  EXPECT_EQ(w.name, "tiny");
  EXPECT_NEAR(w.start.yaw, M_PI / 2, 1e-12);
  ASSERT_EQ(w.solids.size(), 5u);
  EXPECT_EQ(w.solids[1].color, (Rgb{10, 20, 30}));
  EXPECT_EQ(w.solids[0].color, class_color(SemanticClass::kFloor));
  EXPECT_EQ(w.solids[2].shape, Shape::kBox);
  EXPECT_NEAR(w.solids[2].yaw, M_PI / 6, 1e-12);
  EXPECT_EQ(w.solids[3].shape, Shape::kCylinder);
  EXPECT_DOUBLE_EQ(w.solids[3].radius(), 0.2);
  // Explicit ids are kept (and may be shared within a class); the others get fresh unique ids.
  EXPECT_EQ(w.solids[2].instance, 7);
  EXPECT_EQ(w.solids[4].instance, 7);
  std::set<uint16_t> ids;
  for (const auto& s : w.solids) ids.insert(s.instance);
  EXPECT_EQ(ids.size(), 4u);
  EXPECT_EQ(ids.count(0), 0u);
  EXPECT_EQ(w.object_count(), 2);
}

TEST(WorldParse, RoundTripsThroughYaml) {
  const World a = parse_world(kGood, "w.yaml");
  const World b = parse_world(world_to_yaml(a), "again.yaml");
  ASSERT_EQ(a.solids.size(), b.solids.size());
  for (size_t i = 0; i < a.solids.size(); ++i) {
    EXPECT_EQ(a.solids[i].center, b.solids[i].center);
    EXPECT_EQ(a.solids[i].size, b.solids[i].size);
    EXPECT_NEAR(a.solids[i].yaw, b.solids[i].yaw, 1e-12);
    EXPECT_EQ(a.solids[i].instance, b.solids[i].instance);
    EXPECT_EQ(a.solids[i].color, b.solids[i].color);
    EXPECT_EQ(a.solids[i].cls, b.solids[i].cls);
  }
  EXPECT_EQ(a.bounds.min, b.bounds.min);
  EXPECT_EQ(a.start.position, b.start.position);
}

struct BadCase {
  const char* name;
  std::string text;
  const char* where;  // "file:line:" expected in the message
  const char* what;   // a phrase expected in the message
};

TEST(WorldParse, EachBadInputNamesFileAndLine) {
  const std::vector<BadCase> cases = {
      {"unknown class", bad("class: plant", "class: planet"), "w.yaml:8:", "unknown class 'planet'"},
      {"negative size", bad("size: [1.2, 0.8, 0.75]", "size: [1.2, -0.8, 0.75]"), "w.yaml:7:", "positive"},
      {"zero size", bad("size: [1.2, 0.8, 0.75]", "size: [1.2, 0, 0.75]"), "w.yaml:7:", "positive"},
      {"zero radius", bad("radius: 0.2", "radius: 0"), "w.yaml:8:", "radius"},
      {"outside bounds", bad("center: [3.5, 0.5, 0.5]", "center: [4.1, 0.5, 0.5]"),
       "w.yaml:8:", "outside the world bounds"},
      {"start in solid", bad("position: [1, 1, 1.2]", "position: [3, 2, 0.7]"),
       "w.yaml:3:", "intersects solid 2 (table) defined at w.yaml:7:"},
      {"start touching a wall", bad("position: [1, 1, 1.2]", "position: [1, 0.2, 1.2]"),
       "w.yaml:3:", "intersects solid 1 (wall)"},
      {"unknown key", bad("yaw_deg: 30", "yaww_deg: 30"), "w.yaml:7:", "unknown key 'solids[2].yaww_deg'"},
      {"unknown top key", std::string(kGood) + "gravity: 9.81\n", "w.yaml:10:", "unknown key 'gravity'"},
      {"wrong type", bad("height: 1.0", "height: tall"), "w.yaml:8:", "expected a number"},
      {"missing size", bad("size: [1.2, 0.8, 0.75], ", ""), "w.yaml:7:", "'solids[2].size': is required"},
      {"bad shape", bad("type: cylinder", "type: cone"), "w.yaml:8:", "not one of: box, cylinder"},
      {"short vector", bad("center: [3.5, 0.5, 0.5]", "center: [3.5, 0.5]"), "w.yaml:8:", "3 numbers"},
      {"bad colour", bad("color: [10, 20, 30]", "color: [10, 20, 300]"), "w.yaml:6:", "0..255"},
      {"instance shared across classes",
       bad("instance: 7}\n",
           "instance: 7}\n  - {type: box, class: chair, "
           "center: [1, 2, 0.4], size: [0.4, 0.4, 0.8], "
           "instance: 7}\n"),
       "w.yaml:8:", "instance 7 is a chair here but a table at w.yaml:7:"},
      {"empty bounds", bad("max: [4.2, 3.2, 2.8]", "max: [4.2, -3.2, 2.8]"), "w.yaml:2:", "must exceed min"},
      {"yaml syntax", bad("solids:", "solids: ["), "w.yaml:", "YAML syntax error"},
      // What no process could voxelise: named with the line, never std::bad_alloc or a crash.
      {"huge bounds", bad("max: [4.2, 3.2, 2.8]", "max: [1e300, 3.2, 2.8]"), "w.yaml:2:", "at most 200 m"},
      {"too much volume", bad("max: [4.2, 3.2, 2.8]", "max: [150, 150, 12]"), "w.yaml:2:", "m³"},
  };
  for (const auto& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_NE(msg.find(c.where), std::string::npos) << c.name << ": " << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(WorldParse, MissingFileIsAnError) { EXPECT_THROW(load_world("/nonexistent/world.yaml"), WorldError); }

TEST(WorldParse, ValidateWorldChecksBuiltWorlds) {
  World w = test::box_room(4, 3, 2.5);
  w.start.position = {0.1, 1.5, 1.0};  // body pokes into the wall at x = 0
  EXPECT_THROW(validate_world(w), WorldError);
  w.start.position = {2, 1.5, 1.0};
  EXPECT_NO_THROW(validate_world(w));
  w.solids.push_back(
      Solid::box(SemanticClass::kChair, {2, 1.5, 3.0}, {0.4, 0.4, 0.8}));  // through the ceiling
  EXPECT_THROW(validate_world(w), WorldError);
  w.solids.pop_back();
  w.bounds.max.x() = 1e6;
  EXPECT_THROW(validate_world(w), WorldError);
}

// The paper's environments: sizes, ceiling, furnishing and reachability as issue 3 asks.
TEST(ShippedWorlds, MatchThePapersEnvironments) {
  const std::map<std::string, double> nominal = {{"env1", 50}, {"env2", 100}, {"env3", 200}};
  for (const auto& [name, area] : nominal) {
    SCOPED_TRACE(name);
    const World w = test::shipped(name);
    EXPECT_EQ(w.name, name);
    double ceiling = 0;
    for (const auto& s : w.solids) {
      if (s.cls == SemanticClass::kCeiling) ceiling = s.z_min();
    }
    EXPECT_GE(ceiling, 2.5);
    EXPECT_LE(ceiling, 3.0);
    std::map<SemanticClass, int> per_class;
    for (const auto& o : list_objects(w)) ++per_class[o.cls];
    int classes_with_several = 0;
    for (const auto& [c, n] : per_class) classes_with_several += n >= 2;
    EXPECT_GE(classes_with_several, 8);
    const GroundTruth gt(w, 0.1);
    EXPECT_GT(gt.reachable_area(), 0.9 * area);
    EXPECT_LT(gt.reachable_area(), 1.02 * area);
  }
}

}  // namespace
}  // namespace semx::simulator
