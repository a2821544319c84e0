// Random furnished apartments, deterministic per seed, so planners can be tested on worlds
// nobody tuned them to. The footprint is a rectangle of the requested area cut into rooms by a
// guillotine partition; each cut wall gets a doorway (0.9-1.1 m, an open door leaf beside it),
// which keeps every room connected; furniture stands along walls, away from doorways, so each
// room's middle stays open.
#pragma once

#include <cstdint>
#include <vector>

#include "semx/simulator/world.hpp"

namespace semx::simulator {

struct GeneratorOptions {
  uint64_t seed = 1;
  double area = 100.0;  // m², floor area of the whole footprint (interior walls included)
  int rooms = 0;        // 0 = about one per 25 m²
  double ceiling_height = 2.7;
  double wall_thickness = 0.1;
  double flight_height = 1.2;  // z of the start pose
};

struct GeneratedWorld {
  World world;
  std::vector<Aabb> rooms;  // interior of each room (air), for checks and tests
};

// Throws std::invalid_argument for an area or room count that cannot make rooms of at least
// 2.5 m on a side.
GeneratedWorld generate_world(const GeneratorOptions& options);

}  // namespace semx::simulator
