// A recorded-looking message stream for the evaluator node and the log evaluator: ticks of
// SIM_CLOCK with ODOMETRY before them, MAP_UPDATE deltas revealing the small world's ground truth
// (test::sweep_deltas), a COLLISION, PLANNER_STATUS every second and a DONE, in the order the
// processes would put them on the bus.
#pragma once

#include <semx/clock_t.hpp>
#include <semx/map_snapshot_t.hpp>
#include <semx/map_update_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/planner_status_t.hpp>
#include <semx/sim_event_t.hpp>

#include <string>
#include <vector>

#include "evaluator_test_util.hpp"
#include "map_messages.hpp"
#include "semx/evaluator/coverage_tracker.hpp"
#include "semx/map/map_snapshot.hpp"
#include "semx/runtime/channels.hpp"

namespace semx::evaluator::test {

struct SceneEvent {
  std::string channel;
  std::vector<uint8_t> bytes;
  int64_t utime = 0;
};

struct SceneOptions {
  int ticks = 80;              // SIM_CLOCK 0..ticks-1
  int64_t period_us = 100000;  // 0.1 s
  bool clock = true;           // publish SIM_CLOCK
  int deltas = 12;             // at 0.25 s + k * 0.5 s
  int64_t done_us = 5500000;   // planner DONE (-1: never)
  int64_t collision_us = 2000000;
  int64_t episode_end_us = -1;
  int64_t lose_seq = -1;            // this MAP_UPDATE is never sent
  int64_t snapshot_after_seq = -1;  // a MAP_SNAPSHOT of the map at this seq follows its delta
};

inline Eigen::Vector3d scene_position(int64_t utime) { return {0.5 + utime * 1e-6 / 3.0, 1.2, 0.8}; }

template <class T>
SceneEvent scene_event(const char* channel, const T& m) {
  SceneEvent e;
  e.channel = channel;
  e.utime = m.utime;
  e.bytes.resize(static_cast<size_t>(m.getEncodedSize()));
  m.encode(e.bytes.data(), 0, static_cast<int>(e.bytes.size()));
  return e;
}

inline semx::planner_status_t planner_status(int64_t utime, int8_t state, const std::string& reason = "") {
  semx::planner_status_t s{};
  s.utime = utime;
  s.planner = "test-planner";
  s.state = state;
  s.reason = reason;
  return s;
}

inline semx::sim_event_t sim_event(int64_t utime, int8_t type, int64_t count, const std::string& text = "") {
  semx::sim_event_t e{};
  e.utime = utime;
  e.type = type;
  e.description = text;
  e.solid_index = -1;
  e.count = count;
  return e;
}

inline std::vector<SceneEvent> make_scene(const simulator::GroundTruth& gt, const SceneOptions& o) {
  namespace ch = semx::channels;
  const auto deltas = sweep_deltas(gt, o.deltas, 250000, 500000);
  map::StateGrid truth(gt.resolution());
  size_t next_delta = 0;
  std::vector<SceneEvent> out;
  out.push_back(scene_event(ch::SIM_EVENT, sim_event(0, semx::sim_event_t::EPISODE_START, 1, "small")));
  for (int k = 0; k < o.ticks; ++k) {
    const int64_t t = k * o.period_us;
    if (o.episode_end_us >= 0 && t >= o.episode_end_us) {
      out.push_back(
          scene_event(ch::SIM_EVENT, sim_event(t, semx::sim_event_t::EPISODE_END, 1, "time limit")));
      break;
    }
    semx::odometry_t odo{};
    odo.utime = t;
    const Eigen::Vector3d p = scene_position(t);
    for (int i = 0; i < 3; ++i) odo.position[i] = p[i];
    odo.orientation[0] = 1;
    out.push_back(scene_event(ch::ODOMETRY, odo));
    if (t == o.collision_us) {
      out.push_back(
          scene_event(ch::SIM_EVENT, sim_event(t, semx::sim_event_t::COLLISION, 1, "body box hit a solid")));
    }
    if (o.clock) {
      semx::clock_t c{};
      c.utime = t;
      c.tick = k;
      c.mode = semx::clock_t::LOCKSTEP;
      c.period_us = o.period_us;
      out.push_back(scene_event(ch::SIM_CLOCK, c));
    }
    // What the other nodes publish while handling tick k.
    if (k % 10 == 0)
      out.push_back(scene_event(ch::PLANNER_STATUS, planner_status(t, semx::planner_status_t::EXECUTING)));
    if (t == o.done_us) {
      out.push_back(scene_event(ch::PLANNER_STATUS,
                                planner_status(t, semx::planner_status_t::DONE, "no frontier left")));
    }
    while (next_delta < deltas.size() && deltas[next_delta].utime < t + o.period_us) {
      const auto& d = deltas[next_delta++];
      for (const auto& c : d.changes) truth.set_state(c.key, c.state);
      if (d.seq != o.lose_seq) out.push_back(scene_event(ch::MAP_UPDATE, map::to_message(d)));
      if (d.seq == o.snapshot_after_seq) {
        out.push_back(
            scene_event(ch::MAP_SNAPSHOT, map::to_message(map::encode_snapshot(truth, d.seq, d.utime))));
      }
    }
  }
  return out;
}

// Coverage (covered voxels) after the first n deltas of the sweep, from scratch.
inline std::vector<int64_t> covered_after(const simulator::GroundTruth& gt, int deltas) {
  const auto ds = sweep_deltas(gt, deltas, 250000, 500000);
  map::StateGrid grid(gt.resolution());
  std::vector<int64_t> out{0};
  for (const auto& d : ds) {
    for (const auto& c : d.changes) grid.set_state(c.key, c.state);
    out.push_back(CoverageTracker::count_covered(gt, grid));
  }
  return out;
}

}  // namespace semx::evaluator::test
