#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/world_generator.hpp"

namespace semx::simulator {
namespace {

TEST(Generator, ValidFurnishedAndFullyReachableForManySeeds) {
  struct Case {
    double area;
    int rooms;
  };
  for (const Case c :
       {Case{50, 1}, Case{60, 2}, Case{100, 3}, Case{150, 0}, Case{200, 7}, Case{250, 10}, Case{290, 0}}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      SCOPED_TRACE(::testing::Message() << "area " << c.area << " rooms " << c.rooms << " seed " << seed);
      GeneratorOptions o;
      o.seed = seed;
      o.area = c.area;
      o.rooms = c.rooms;
      GeneratedWorld g = generate_world(o);
      World& w = g.world;
      if (c.rooms > 0) {
        EXPECT_EQ(static_cast<int>(g.rooms.size()), c.rooms);
      }
      // Valid as a file: it round-trips through the strict parser (start not in a solid, all
      // solids in bounds).
      const World parsed = parse_world(world_to_yaml(w), "generated.yaml");
      EXPECT_EQ(parsed.solids.size(), w.solids.size());
      EXPECT_LT(first_solid_hit_by_body(w, w.start.position, w.start.yaw), 0);
      const GroundTruth gt(w, 0.1);
      EXPECT_GT(gt.reachable_area(), 0.9 * c.area);
      EXPECT_LT(gt.reachable_area(), 1.05 * c.area);
      // Every room is reachable by the vehicle at flight height, not only by air.
      const VehicleReachability vr(gt, w.start.position);
      for (const auto& room : g.rooms) {
        const Eigen::Vector3d mid(room.center().x(), room.center().y(), o.flight_height);
        // Room middles can hold a table and chairs: look for a reachable point near the middle.
        bool ok = false;
        for (double dx = -0.5; dx <= 0.5 && !ok; dx += 0.25) {
          for (double dy = -0.5; dy <= 0.5 && !ok; dy += 0.25)
            ok = vr.reachable(mid + Eigen::Vector3d(dx, dy, 0));
        }
        EXPECT_TRUE(ok) << "room at " << room.center().transpose();
      }
      std::set<SemanticClass> classes;
      for (const auto& obj : gt.objects()) classes.insert(obj.cls);
      EXPECT_GE(classes.size(), c.rooms == 1 ? 5u : 8u);
    }
  }
}

TEST(Generator, DeterministicPerSeed) {
  GeneratorOptions o;
  o.area = 120;
  o.rooms = 4;
  o.seed = 17;
  const std::string a = world_to_yaml(generate_world(o).world);
  const std::string b = world_to_yaml(generate_world(o).world);
  o.seed = 18;
  const std::string c = world_to_yaml(generate_world(o).world);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(Generator, RejectsImpossibleRequests) {
  GeneratorOptions o;
  o.area = 20;
  o.rooms = 6;  // 3.3 m² rooms cannot be 2.5 m a side
  EXPECT_THROW(generate_world(o), std::invalid_argument);
  o.area = -5;
  o.rooms = 1;
  EXPECT_THROW(generate_world(o), std::invalid_argument);
}

}  // namespace
}  // namespace semx::simulator
