// semx-map-compare: how far two maps (mapper checkpoints) agree, voxel by voxel: of the voxels
// known (free or occupied) in the reference, the share the other map holds in the same state.
// The ROS bag round trip (docs/ros.md) is judged with it.
#include <cstdio>
#include <iostream>

#include "semx/mapper/checkpoint.hpp"
#include "semx/mapper/mapper_config.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-map-compare", [&] {
    std::string reference, other;
    double min_agreement = -1.0;
    runtime::ArgParser p("semx-map-compare",
                         "Compares two mapper checkpoints: of the voxels known in REFERENCE, how many OTHER "
                         "holds in the same state (free/occupied), and how many it leaves unknown.");
    p.positional("REFERENCE", "checkpoint of the reference map", &reference)
        .positional("OTHER", "checkpoint of the map to judge", &other)
        .option("min", "PERCENT", "exit 1 when the agreement is below PERCENT", &min_agreement);
    if (!p.parse(argc, argv)) return 0;
    const double resolution = mapper::read_checkpoint_info(reference).resolution;
    mapper::OccupancyParams params = mapper::MapperConfig{}.occupancy;
    params.resolution = resolution;
    mapper::OccupancyMap a(params), b(params);
    mapper::load_checkpoint(reference, a);
    mapper::load_checkpoint(other, b);
    int64_t known = 0, same = 0, unknown = 0;
    a.grid().for_each_block([&](const map::VoxelKey& bk, const map::VoxelBlock& block) {
      if (block.known == 0) return;
      for (int i = 0; i < map::kBlockVolume; ++i) {
        const map::VoxelState s = block.state[static_cast<std::size_t>(i)];
        if (s == map::VoxelState::kUnknown) continue;
        ++known;
        const map::VoxelState t = b.grid().state(map::voxel_of(bk, i));
        if (t == s) ++same;
        if (t == map::VoxelState::kUnknown) ++unknown;
      }
    });
    const double pct = known > 0 ? 100.0 * static_cast<double>(same) / static_cast<double>(known) : 0.0;
    std::printf("semx-map-compare: reference %lld known voxels (other %lld); same state %lld (%.3f %%), unknown in "
                "other %lld, other state %lld\n",
                static_cast<long long>(known), static_cast<long long>(b.grid().known_voxels()),
                static_cast<long long>(same), pct, static_cast<long long>(unknown),
                static_cast<long long>(known - same - unknown));
    return min_agreement >= 0 && pct < min_agreement ? 1 : 0;
  });
}
