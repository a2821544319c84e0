// Deltas, snapshots and the map mirror (what MAP_UPDATE / MAP_SNAPSHOT carry).
#include <gtest/gtest.h>

#include <deque>
#include <set>

#include "mapper_test_util.hpp"

namespace semx::mapper {
namespace {

void expect_same(const map::StateGrid& a, const map::StateGrid& b) {
  map::VoxelKey diff;
  const bool same = a.same_states(b, &diff);
  EXPECT_TRUE(same) << "first difference at " << diff.x << " " << diff.y << " " << diff.z << ": "
                    << to_string(a.state(diff)) << " vs " << to_string(b.state(diff));
  EXPECT_EQ(a.free_voxels(), b.free_voxels());
  EXPECT_EQ(a.occupied_voxels(), b.occupied_voxels());
}

TEST(Streaming, SnapshotRoundTripIsExact) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  for (const auto& f : test::room_frames(6, cam, 6)) mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
  const map::MapSnapshot snap = mapper.snapshot(123);
  EXPECT_EQ(snap.seq, 6);
  EXPECT_EQ(snap.utime, 123);
  EXPECT_EQ(snap.encoding, map::kSnapshotBlocksZlib);
  map::StateGrid copy(0.1);
  map::decode_snapshot(snap, copy);
  expect_same(mapper.map().grid(), copy);
  EXPECT_EQ(copy.count_frontiers(), mapper.map().count_frontiers());
  // Deterministic: the same map encodes to the same bytes; and it is compressed.
  EXPECT_EQ(map::encode_snapshot(copy, 6, 123).data, snap.data);
  EXPECT_LT(snap.data.size(), static_cast<size_t>(mapper.map().grid().known_voxels() / 4));
}

TEST(Streaming, EmptyMapSnapshot) {
  map::StateGrid empty(0.1), out(0.1);
  out.set_state({1, 2, 3}, map::VoxelState::kFree);
  map::decode_snapshot(map::encode_snapshot(empty, 0), out);
  EXPECT_EQ(out.known_voxels(), 0);
  EXPECT_EQ(out.state(map::VoxelKey{1, 2, 3}), map::VoxelState::kUnknown);
}

TEST(Streaming, MalformedSnapshotsAreRejectedAndLeaveTheMirrorAlone) {
  map::StateGrid g(0.1);
  for (int i = 0; i < 50; ++i)
    g.set_state({i, -i, 2 * i}, i % 3 ? map::VoxelState::kFree : map::VoxelState::kOccupied);
  const map::MapSnapshot good = map::encode_snapshot(g, 5);
  map::MapMirror mirror(0.1);
  ASSERT_EQ(mirror.apply(good), map::MapMirror::SnapshotResult::kApplied);

  auto rejected = [&](map::MapSnapshot s, const char* what) {
    s.seq = 9;  // newer, so that only its content can make the mirror refuse it
    EXPECT_EQ(mirror.apply(s), map::MapMirror::SnapshotResult::kRejected) << what;
    EXPECT_EQ(mirror.seq(), 5) << what;
    expect_same(mirror.grid(), g);
  };
  map::MapSnapshot s = good;
  s.data.resize(s.data.size() / 2);
  rejected(s, "truncated");
  s = good;
  s.data[s.data.size() / 2] ^= 0x5A;
  rejected(s, "flipped byte");
  s = good;
  s.encoding = 7;
  rejected(s, "unknown encoding");
  s = good;
  s.resolution = 0.2;
  rejected(s, "resolution");
  s = good;
  s.data.assign({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F, 1, 2, 3});
  rejected(s, "absurd size");
  s = good;
  s.data.clear();
  rejected(s, "empty");
  EXPECT_FALSE(mirror.last_error().empty());
  EXPECT_EQ(mirror.counters().snapshots_rejected, 6);
}

TEST(Streaming, MirrorFollowsEveryDelta) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  map::MapMirror mirror(0.1);
  for (const auto& f : test::room_frames(5, cam, 5)) {
    const FrameResult r = mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
    std::vector<map::VoxelState> before;
    for (const map::VoxelChange& c : r.delta.changes) before.push_back(mirror.grid().state(c.key));
    ASSERT_EQ(mirror.apply(r.delta), map::MapMirror::DeltaResult::kApplied);
    ASSERT_EQ(mirror.seq(), mapper.seq());
    expect_same(mirror.grid(), mapper.map().grid());
    // What it hands on: the same changes, each with the state it replaced.
    const map::MapDelta& applied = mirror.last_applied();
    EXPECT_EQ(applied.seq, r.delta.seq);
    ASSERT_EQ(applied.changes.size(), r.delta.changes.size());
    for (size_t i = 0; i < applied.changes.size(); ++i) {
      EXPECT_EQ(applied.changes[i].key, r.delta.changes[i].key);
      EXPECT_EQ(applied.changes[i].state, r.delta.changes[i].state);
      ASSERT_TRUE(applied.changes[i].previous);
      EXPECT_EQ(*applied.changes[i].previous, before[i]);
    }
  }
}

// The acceptance test: deltas lost on the way, the mirror asks for a snapshot, which
// arrives a couple of frames later; at the end the mirror equals the map exactly.
TEST(Streaming, MirrorRecoversFromLostDeltasBySnapshot) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  map::MapMirror mirror(0.1);
  const std::set<int64_t> lost = {3, 7, 8, 15};
  std::deque<map::MapSnapshot> in_flight;  // snapshot requests are answered with a delay
  int requests = 0;
  bool requested = false;
  for (const auto& f : test::room_frames(20, cam, 20)) {
    const FrameResult r = mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
    ASSERT_TRUE(r.report.accepted);
    if (!lost.count(r.delta.seq)) mirror.apply(r.delta);
    // A snapshot asked for earlier arrives after this frame's delta, which must be kept.
    if (!in_flight.empty()) {
      mirror.apply(in_flight.front());
      in_flight.pop_front();
      requested = false;
    }
    if (mirror.needs_snapshot() && !requested) {
      ++requests;
      requested = true;
      in_flight.push_back(mapper.snapshot());  // taken now, delivered next frame
    }
  }
  while (!in_flight.empty()) {
    mirror.apply(in_flight.front());
    in_flight.pop_front();
  }
  EXPECT_FALSE(mirror.needs_snapshot());
  EXPECT_EQ(mirror.seq(), mapper.seq());
  expect_same(mirror.grid(), mapper.map().grid());
  EXPECT_EQ(mirror.counters().gaps, 3) << "7 and 8 are one gap";
  EXPECT_EQ(requests, 3);
  EXPECT_EQ(mirror.counters().snapshots_applied, 3);
  // The deltas that arrived while waiting (4 5, 9 10, 16 17) were kept, and those newer than
  // the snapshot (5, 10, 17) applied after it: every delivered delta but the gap-revealing ones.
  EXPECT_EQ(mirror.counters().deltas_buffered, 6);
  EXPECT_EQ(mirror.counters().deltas_applied, 20 - 4 - 3);
}

TEST(Streaming, MirrorRefusesDeltasAfterAGapUntilASnapshot) {
  map::MapMirror mirror(0.1);
  map::MapDelta d1{1, 0, 0.1, {{{0, 0, 0}, map::VoxelState::kFree}}};
  map::MapDelta d3{3, 0, 0.1, {{{2, 0, 0}, map::VoxelState::kOccupied}}};
  EXPECT_EQ(mirror.apply(d1), map::MapMirror::DeltaResult::kApplied);
  EXPECT_EQ(mirror.apply(d3), map::MapMirror::DeltaResult::kBuffered);
  EXPECT_TRUE(mirror.needs_snapshot());
  EXPECT_EQ(mirror.state(map::VoxelKey{2, 0, 0}), map::VoxelState::kUnknown) << "not applied across the gap";
  map::MapDelta d4{4, 0, 0.1, {{{3, 0, 0}, map::VoxelState::kFree}}};
  EXPECT_EQ(mirror.apply(d4), map::MapMirror::DeltaResult::kBuffered);
  // The mapper's map at seq 2, as a snapshot: then 3 and 4 are applied from the buffer.
  map::StateGrid at2(0.1);
  at2.set_state({0, 0, 0}, map::VoxelState::kFree);
  at2.set_state({1, 0, 0}, map::VoxelState::kFree);
  EXPECT_EQ(mirror.apply(map::encode_snapshot(at2, 2)), map::MapMirror::SnapshotResult::kApplied);
  EXPECT_FALSE(mirror.needs_snapshot());
  EXPECT_EQ(mirror.seq(), 4);
  EXPECT_EQ(mirror.state(map::VoxelKey{1, 0, 0}), map::VoxelState::kFree);
  EXPECT_EQ(mirror.state(map::VoxelKey{2, 0, 0}), map::VoxelState::kOccupied);
  EXPECT_EQ(mirror.state(map::VoxelKey{3, 0, 0}), map::VoxelState::kFree);
  // An old snapshot is ignored while in sequence.
  EXPECT_EQ(mirror.apply(map::encode_snapshot(at2, 2)), map::MapMirror::SnapshotResult::kIgnored);
  // Wrong resolution and out-of-range keys are rejected without touching the mirror.
  map::MapDelta bad_res{5, 0, 0.2, {}};
  EXPECT_EQ(mirror.apply(bad_res), map::MapMirror::DeltaResult::kRejected);
  map::MapDelta bad_key{5, 0, 0.1, {{{map::kMaxKeyMagnitude, 0, 0}, map::VoxelState::kFree}}};
  EXPECT_EQ(mirror.apply(bad_key), map::MapMirror::DeltaResult::kRejected);
  map::MapDelta bad_state{5, 0, 0.1, {{{0, 0, 0}, static_cast<map::VoxelState>(9)}}};
  EXPECT_EQ(mirror.apply(bad_state), map::MapMirror::DeltaResult::kRejected);
  EXPECT_EQ(mirror.seq(), 4);
  EXPECT_FALSE(mirror.needs_snapshot());
  // Updates the mirror holds already: the snapshot of map 6 came before updates 5 and 6 (two
  // channels, not ordered against each other on a lossy bus). Not a gap; update 7 follows.
  map::StateGrid at6(0.1);
  for (const auto& [k, st] :
       std::vector<std::pair<map::VoxelKey, map::VoxelState>>{{{0, 0, 0}, map::VoxelState::kFree},
                                                              {{1, 0, 0}, map::VoxelState::kFree},
                                                              {{2, 0, 0}, map::VoxelState::kOccupied},
                                                              {{3, 0, 0}, map::VoxelState::kFree}})
    at6.set_state(k, st);
  at6.set_state({4, 0, 0}, map::VoxelState::kOccupied);
  at6.set_state({5, 0, 0}, map::VoxelState::kOccupied);
  EXPECT_EQ(mirror.apply(map::encode_snapshot(at6, 6)), map::MapMirror::SnapshotResult::kApplied);
  const int64_t gaps = mirror.counters().gaps;
  map::MapDelta d5{5, 0, 0.1, {{{4, 0, 0}, map::VoxelState::kOccupied}}};
  map::MapDelta d6{6, 0, 0.1, {{{5, 0, 0}, map::VoxelState::kOccupied}}};
  map::MapDelta d7{7, 0, 0.1, {{{6, 0, 0}, map::VoxelState::kFree}}};
  EXPECT_EQ(mirror.apply(d5), map::MapMirror::DeltaResult::kIgnored);
  EXPECT_EQ(mirror.apply(d6), map::MapMirror::DeltaResult::kIgnored);
  EXPECT_EQ(mirror.apply(d7), map::MapMirror::DeltaResult::kApplied);
  EXPECT_EQ(mirror.counters().gaps, gaps);
  EXPECT_EQ(mirror.state(map::VoxelKey{5, 0, 0}), map::VoxelState::kOccupied);
  EXPECT_EQ(mirror.state(map::VoxelKey{6, 0, 0}), map::VoxelState::kFree);
  // An update at or below the last one applied is a mapper that began again: a gap.
  map::MapDelta again{2, 0, 0.1, {{{1, 0, 0}, map::VoxelState::kOccupied}}};
  EXPECT_EQ(mirror.apply(again), map::MapMirror::DeltaResult::kBuffered);
  EXPECT_TRUE(mirror.needs_snapshot());
  EXPECT_EQ(mirror.counters().gaps, gaps + 1);
}

TEST(Streaming, MapperRestartMakesMirrorsResynchronise) {
  const runtime::PinholeCamera cam = test::small_camera();
  const auto frames = test::room_frames(6, cam, 6);
  const std::string path = test::temp_path("restart.map");
  auto first = std::make_unique<Mapper>(MapperConfig{});
  map::MapMirror mirror(0.1);
  for (int i = 0; i < 4; ++i) {
    mirror.apply(first->integrate(DepthFrame::view(cam, frames[i].pose, frames[i].depth)).delta);
    if (i == 1) first->save_checkpoint(path, 0);  // checkpoint at seq 2, then two more frames
  }
  ASSERT_EQ(mirror.seq(), 4);
  first.reset();  // the mapper dies

  // Restarted from the checkpoint: its map lacks frames 3 and 4, which the mirror has.
  Mapper second{MapperConfig{}};
  second.load_checkpoint(path);
  EXPECT_EQ(second.seq(), 2 + Mapper::kRestoreSequenceJump);
  const FrameResult r = second.integrate(DepthFrame::view(cam, frames[4].pose, frames[4].depth));
  EXPECT_EQ(mirror.apply(r.delta), map::MapMirror::DeltaResult::kBuffered);
  EXPECT_TRUE(mirror.needs_snapshot());
  EXPECT_EQ(mirror.apply(second.snapshot()), map::MapMirror::SnapshotResult::kApplied);
  expect_same(mirror.grid(), second.map().grid());

  // A mapper restarted without a checkpoint begins again at seq 1: also a resync.
  Mapper fresh{MapperConfig{}};
  const FrameResult f1 = fresh.integrate(DepthFrame::view(cam, frames[5].pose, frames[5].depth));
  EXPECT_EQ(mirror.apply(f1.delta), map::MapMirror::DeltaResult::kBuffered);
  EXPECT_EQ(mirror.apply(fresh.snapshot()), map::MapMirror::SnapshotResult::kApplied);
  expect_same(mirror.grid(), fresh.map().grid());
  std::remove(path.c_str());
}

TEST(Streaming, StatsCountVolumesAndFrontiers) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  for (const auto& f : test::room_frames(3, cam, 3)) mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
  const map::MapStats s = mapper.stats();
  const map::StateGrid& g = mapper.map().grid();
  EXPECT_EQ(s.seq, 3);
  EXPECT_EQ(s.free_voxels, g.free_voxels());
  EXPECT_NEAR(s.free_m3, g.free_voxels() * 1e-3, 1e-9);
  EXPECT_NEAR(s.occupied_m3, g.occupied_voxels() * 1e-3, 1e-9);
  EXPECT_NEAR(s.known_m3, s.free_m3 + s.occupied_m3, 1e-9);
  EXPECT_EQ(s.frontier_voxels, g.count_frontiers());
  EXPECT_GT(s.frontier_voxels, 0);
  EXPECT_EQ(s.frames_integrated, 3);
  // The room is 6 x 5 x 2.7 m with its corner at the origin: known space hugs it.
  EXPECT_GT(s.bounds_min.x(), -0.21);
  EXPECT_LT(s.bounds_max.x(), 6.21);
  EXPECT_EQ(mapper.stats(false).frontier_voxels, -1);
  // Free and occupied counts agree with a full scan.
  int64_t free = 0, occ = 0;
  g.for_each_block([&](const map::VoxelKey&, const map::VoxelBlock& b) {
    for (map::VoxelState st : b.state) {
      free += st == map::VoxelState::kFree;
      occ += st == map::VoxelState::kOccupied;
    }
  });
  EXPECT_EQ(free, s.free_voxels);
  EXPECT_EQ(occ, s.occupied_voxels);
}

}  // namespace
}  // namespace semx::mapper
