// Conversions between the map's values and the map messages (MAP_UPDATE, MAP_SNAPSHOT,
// MAP_REQUEST, MAP_STATS, ESDF_LOCAL; docs/messages.md), and the content checks subscriptions
// use as `accept` predicates. The map library knows no messages; this file is the only place
// that knows both, for the mapper that sends them and every process that reads them.
#pragma once

#include <semx/esdf_local_t.hpp>
#include <semx/map_request_t.hpp>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_stats_t.hpp>
#include <semx/map_update_t.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "semx/map/esdf_grid.hpp"
#include "semx/map/map_delta.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/map/map_stats.hpp"

namespace semx::map {

// ---- MAP_UPDATE (map_update_t) ----

semx::map_update_t to_message(const MapDelta& d);
// False (and `out` unspecified) when the arrays disagree with num_voxels, a state is not 0..2 or
// the resolution is not finite and positive.
bool from_message(const semx::map_update_t& m, MapDelta& out);
bool accept_update(const semx::map_update_t& m);

// ---- MAP_SNAPSHOT (map_snapshot_t) ----

semx::map_snapshot_t to_message(const MapSnapshot& s);
MapSnapshot from_message(const semx::map_snapshot_t& m);
// Sizes and resolution only; the payload is checked when it is decoded (MapMirror).
bool accept_snapshot(const semx::map_snapshot_t& m);

// ---- MAP_REQUEST (map_request_t) ----

semx::map_request_t request_message(const std::string& requester, int64_t last_seq, int64_t utime);
bool accept_request(const semx::map_request_t& m);

// ---- MAP_STATS (map_stats_t) ----

semx::map_stats_t to_message(const MapStats& s, int64_t utime);

// ---- ESDF_LOCAL (esdf_local_t) ----

// origin = the window's minimum corner in metres (EsdfGrid::origin_point()).
semx::esdf_local_t to_message(const EsdfGrid& g, int64_t utime);
// The inverse (the origin key is the corner divided by the resolution, rounded); false for
// inconsistent sizes or values that are not finite.
bool from_message(const semx::esdf_local_t& m, EsdfGrid& out);

}  // namespace semx::map
