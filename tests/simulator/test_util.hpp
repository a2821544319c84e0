// Small builders shared by the simulator tests.
#pragma once

#include <string>

#include "semx/simulator/world.hpp"

namespace semx::simulator::test {

// A closed box room: interior [0, sx] x [0, sy] x [0, sz], slabs `t` thick outside it.
inline World box_room(double sx, double sy, double sz, double t = 0.2) {
  World w;
  w.name = "room";
  w.bounds = {{-t, -t, -t}, {sx + t, sy + t, sz + t}};
  w.start.position = {sx / 2, sy / 2, sz / 2};
  using C = SemanticClass;
  w.solids.push_back(Solid::box(C::kFloor, {sx / 2, sy / 2, -t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(Solid::box(C::kCeiling, {sx / 2, sy / 2, sz + t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(Solid::box(C::kWall, {-t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx + t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx / 2, -t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx / 2, sy + t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  return w;
}

inline World shipped(const std::string& name) { return load_world(shipped_world_path(name)); }

}  // namespace semx::simulator::test
