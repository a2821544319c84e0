#include "semx/mapper/mapper_config.hpp"

#include <cmath>

namespace semx::mapper {

namespace {
[[noreturn]] void invalid(const std::string& what) { throw runtime::ConfigError("mapper config: " + what); }

// The per-frame scratch grid spans the view frustum; this keeps it below 2^27 cells.
constexpr double kMaxRangeInVoxels = 250.0;
constexpr double kMaxEsdfCells = 8.0e6;
constexpr double kMaxBoundVoxels = 30000.0;
}  // namespace

void load(runtime::ConfigMap& m, MapperConfig& c) {
  m.get("resolution", c.occupancy.resolution, 0.01, 1.0);

  runtime::ConfigMap occ = m.child("occupancy");
  occ.get("prob_hit", c.occupancy.prob_hit, 0.5, 0.999);
  occ.get("prob_miss", c.occupancy.prob_miss, 0.001, 0.5);
  occ.get("clamp_min", c.occupancy.clamp_min, 0.001, 0.5);
  occ.get("clamp_max", c.occupancy.clamp_max, 0.5, 0.999);
  occ.get("threshold", c.occupancy.threshold, 0.001, 0.999);
  occ.get("hold_range", c.occupancy.hold_range, 0.0, 100.0);
  occ.get("bounds_min", c.occupancy.bounds_min);
  occ.get("bounds_max", c.occupancy.bounds_max);

  runtime::ConfigMap in = m.child("integration");
  in.get("min_range", c.integration.min_range, 0.0, 100.0);
  in.get("max_range", c.integration.max_range, 0.05, 100.0);
  in.get("pixel_step", c.integration.pixel_step, 1, 16);
  in.get("frame_period_s", c.integration.frame_period_s, 0.0, 3600.0);
  std::string mode = to_string(c.integration.mode);
  in.get_choice("mode", mode, {"exact", "bundled", "fast"});
  c.integration.mode =
      mode == "exact" ? IntegrationParams::Mode::kExact
                      : (mode == "fast" ? IntegrationParams::Mode::kFast : IntegrationParams::Mode::kBundled);

  runtime::ConfigMap esdf = m.child("esdf");
  esdf.get("enabled", c.esdf.enabled);
  esdf.get("window", c.esdf.window);
  esdf.get("max_distance", c.esdf.max_distance, 0.01, 100.0);
  esdf.get("unknown_as_occupied", c.esdf.unknown_as_occupied);

  runtime::ConfigMap st = m.child("streaming");
  st.get("snapshot_period", c.streaming.snapshot_period, 0.0, 3600.0);
  st.get("stats_period", c.streaming.stats_period, 0.0, 3600.0);
  st.get("esdf_period", c.streaming.esdf_period, 0.0, 3600.0);
  st.get("lockstep_delay", c.streaming.lockstep_delay, 0.0, 10.0);

  runtime::ConfigMap cp = m.child("checkpoint");
  cp.get("path", c.checkpoint.path);
  cp.get("period", c.checkpoint.period, 0.0, 86400.0);

  try {
    validate(c);
  } catch (const runtime::ConfigError& e) {
    throw runtime::ConfigError(m.where() + ": " + e.what());
  }
}

const char* to_string(IntegrationParams::Mode m) {
  switch (m) {
    case IntegrationParams::Mode::kExact:
      return "exact";
    case IntegrationParams::Mode::kBundled:
      return "bundled";
    case IntegrationParams::Mode::kFast:
      return "fast";
  }
  return "?";
}

void validate(const OccupancyParams& o) {
  if (!(o.resolution >= 0.01 && o.resolution <= 1.0)) invalid("resolution must be in [0.01, 1] m");
  if (!(o.prob_hit > 0.5 && o.prob_hit < 1.0)) invalid("occupancy.prob_hit must be in (0.5, 1)");
  if (!(o.prob_miss > 0.0 && o.prob_miss < 0.5)) invalid("occupancy.prob_miss must be in (0, 0.5)");
  if (!(o.clamp_min > 0.0 && o.clamp_min < o.threshold && o.threshold < o.clamp_max && o.clamp_max < 1.0)) {
    invalid("occupancy needs 0 < clamp_min < threshold < clamp_max < 1");
  }
  if (o.bounds_min.empty() != o.bounds_max.empty())
    invalid("occupancy.bounds_min and bounds_max go together");
  if (!o.bounds_min.empty()) {
    if (o.bounds_min.size() != 3 || o.bounds_max.size() != 3)
      invalid("occupancy.bounds_* need 3 numbers (x y z)");
    for (int i = 0; i < 3; ++i) {
      if (!(o.bounds_min[i] < o.bounds_max[i])) invalid("occupancy.bounds_min must be below bounds_max");
      // OctoMap's keys (map.bt, checkpoints) are 16 bits around the origin: a bound beyond them
      // (±1e9 m) wrapped every voxel and the run reported 0 % and DONE at 2 s.
      const double limit = kMaxBoundVoxels * o.resolution;
      if (!(std::abs(o.bounds_min[i]) <= limit && std::abs(o.bounds_max[i]) <= limit))
        invalid("occupancy.bounds_* must lie within ±" + std::to_string(static_cast<int64_t>(limit)) +
                " m (30000 voxels of the resolution: OctoMap's 16-bit keys)");
    }
  }
}

void validate(const MapperConfig& c) {
  const OccupancyParams& o = c.occupancy;
  validate(o);
  const IntegrationParams& in = c.integration;
  if (!(in.max_range > 0.0 && in.min_range >= 0.0 && in.min_range < in.max_range)) {
    invalid("integration needs 0 <= min_range < max_range");
  }
  if (in.max_range / o.resolution > kMaxRangeInVoxels) {
    invalid("integration.max_range / resolution must be at most " + std::to_string(kMaxRangeInVoxels) +
            " (the per-frame scratch grid spans the view frustum)");
  }
  if (in.pixel_step < 1) invalid("integration.pixel_step must be >= 1");
  const EsdfParams& e = c.esdf;
  if (e.window.size() != 3) invalid("esdf.window needs 3 numbers (x y z extent, m)");
  double cells = 1.0;
  for (double w : e.window) {
    if (!(w >= 2.0 * o.resolution && w <= 100.0))
      invalid("esdf.window extents must be in [2*resolution, 100] m");
    cells *= std::ceil(w / o.resolution);
  }
  if (cells > kMaxEsdfCells) invalid("esdf.window holds more than 8e6 voxels at this resolution");
  if (!(e.max_distance > 0.0)) invalid("esdf.max_distance must be positive");
}

}  // namespace semx::mapper
