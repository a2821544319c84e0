// semx-map-replay: rebuilds a map from an lcm-logger log's CAMERA_DEPTH frames (no network) and
// writes a checkpoint, an OctoMap .bt and a .pcd of the occupied voxels.
#include <algorithm>
#include <cstdio>
#include <iostream>

#include "map_replay.hpp"
#include "semx/runtime/args.hpp"
#include "semx/runtime/config.hpp"

using namespace semx;

int main(int argc, char** argv) {
  return runtime::run_main("semx-map-replay", [&] {
    std::string log, out = ".", config_file, channel = "CAMERA_DEPTH";
    std::vector<std::string> overrides;
    runtime::ArgParser p(
        "semx-map-replay",
        "Rebuilds a map from the depth frames of an lcm-logger log, as semx-mapper would have\n"
        "built it, and writes DIR/map.ckpt (checkpoint), DIR/map.bt (octovis) and DIR/map.pcd\n"
        "(occupied voxels, pcl_viewer).");
    p.positional("LOG", "lcm-logger log file", &log)
        .option("out", "DIR", "output directory, created if needed (default: .)", &out)
        .option("config", "FILE", "mapper YAML (docs/mapper.md)", &config_file)
        .repeated("set", "KEY=VALUE", "override one config key, e.g. --set resolution=0.05", &overrides)
        .option("channel", "NAME", "depth channel (default CAMERA_DEPTH)", &channel);
    if (!p.parse(argc, argv)) return 0;
    const auto config = runtime::load_config<mapper::MapperConfig>(config_file, overrides);
    mapper::Mapper m(config);

    mapper::ReplayOptions o;
    o.log_path = log;
    o.channel = channel;
    mapper::ReplayReport r;
    try {
      r = mapper::replay_log(o, m);
    } catch (const mapper::ReplayError& e) {
      std::cerr << "semx-map-replay: " << e.what() << "\n";
      return 1;
    }
    std::printf("semx-map-replay: %s: %lld events, %lld on %s\n", log.c_str(),
                static_cast<long long>(r.layout.events), static_cast<long long>(r.depth_events),
                channel.c_str());
    if (r.layout.truncated) {
      std::printf(
          "semx-map-replay: warning: the log ends inside an event at byte %llu (cut short while "
          "recording?); read the %lld complete events before it\n",
          static_cast<unsigned long long>(r.layout.truncated_at), static_cast<long long>(r.layout.events));
    }
    if (!r.left_out.empty()) std::printf("semx-map-replay: warning: %s\n", r.left_out.c_str());
    if (r.depth_events == 0) {
      std::string seen;
      for (const auto& [name, n] : r.channels)
        seen += (seen.empty() ? "" : ", ") + name + " " + std::to_string(n);
      std::cerr << "semx-map-replay: " << log << ": no " << channel << " events (channels: " << seen << ")\n";
      return 1;
    }
    std::printf(
        "semx-map-replay: frames integrated %lld, skipped %lld (frame_period_s), rejected %lld, "
        "malformed %lld%s%s\n",
        static_cast<long long>(r.integrated), static_cast<long long>(r.skipped),
        static_cast<long long>(r.rejected), static_cast<long long>(r.malformed),
        r.first_error.empty() ? "" : "; first problem: ", r.first_error.c_str());
    if (r.integrated == 0) {
      std::cerr << "semx-map-replay: " << log << ": none of the " << r.depth_events
                << " frames could be integrated; nothing written\n";
      return 1;
    }
    const map::MapStats s = m.stats(true);
    std::printf(
        "semx-map-replay: map seq %lld: %lld free + %lld occupied voxels (%.2f m3 known), %lld frontier "
        "voxels, bounds [%.2f %.2f %.2f] .. [%.2f %.2f %.2f] m\n",
        static_cast<long long>(s.seq), static_cast<long long>(s.free_voxels),
        static_cast<long long>(s.occupied_voxels), s.known_m3, static_cast<long long>(s.frontier_voxels),
        s.bounds_min.x(), s.bounds_min.y(), s.bounds_min.z(), s.bounds_max.x(), s.bounds_max.y(),
        s.bounds_max.z());
    std::printf("semx-map-replay: %.3f s of simulation time; integration %.2f ms per frame (%.1f frames/s)\n",
                1e-6 * static_cast<double>(r.last_utime - r.first_utime),
                1e3 * r.integrate_s / static_cast<double>(r.integrated),
                static_cast<double>(r.integrated) / std::max(1e-9, r.integrate_s));
    for (const auto& f : mapper::write_map_files(m, out, std::max<int64_t>(0, r.last_utime))) {
      std::printf("semx-map-replay: wrote %s\n", f.c_str());
    }
    return 0;
  });
}
