// A world: bounds, the vehicle's start pose and the solids, read from the YAML format of
// docs/worlds.md. Reading is strict: every malformed input is an error naming file and line.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "semx/runtime/config.hpp"
#include "semx/simulator/solid.hpp"

namespace semx::simulator {

// The vehicle's body box (x forward, y left, z up), used for the start check and collisions.
inline const Eigen::Vector3d kVehicleSize{0.5, 0.5, 0.3};

struct StartPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

struct World {
  std::string name;
  // Every solid lies inside `bounds`; ground-truth free space is flooded only inside it.
  Aabb bounds;
  StartPose start;
  std::vector<Solid> solids;
  std::string source;  // file the world came from, for messages

  // Number of distinct instances of non-structural classes.
  int object_count() const;
  // Highest instance id in use (auto-assigned ids continue from here).
  uint16_t max_instance() const;
};

using WorldError = runtime::ConfigError;

// What a world may hold: every process voxelises it at the map's resolution (0.1 m) and the
// ground truth floods its free space, so a box of ±1e6 m is std::bad_alloc, not a world. 200 m
// a side and 2e5 m³ (2e8 voxels at 0.1 m: a 2 GB ground truth at most) leave every indoor scene
// room; 1e5 solids is 20× the largest generated world.
constexpr double kMaxWorldExtent = 200.0;   // m, each axis of the bounds
constexpr double kMaxWorldVolume = 2.0e5;   // m³, the bounds' volume
constexpr size_t kMaxWorldSolids = 100000;

// Reads a world file; throws WorldError "file:line:col: ..." on any malformed input.
World load_world(const std::string& file);
World parse_world(const std::string& text, const std::string& source);

// Writes a world in the file format (round-trips through parse_world).
std::string world_to_yaml(const World& world);
void save_world(const World& world, const std::string& file);

// The semantic checks of the parser for worlds built in code (the generator); messages name
// solids by index instead of line. Also assigns instance ids to solids that have none.
void validate_world(World& world);

// Index of a solid the vehicle body would intersect at `position` / `yaw`, or -1.
int first_solid_hit_by_body(const World& world, const Eigen::Vector3d& position, double yaw,
                            const Eigen::Vector3d& body_size = kVehicleSize);

// Path of a world shipped in simulator/worlds ("env1" -> ".../worlds/env1.yaml"); a name with
// a '/' or ending in .yaml is returned unchanged.
std::string shipped_world_path(const std::string& name);

}  // namespace semx::simulator
