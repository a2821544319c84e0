#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "semx/core/time_split.hpp"

namespace semx::core {
namespace {

// A scripted run at 100 Hz, 40 s of it:
//   0-4 s    turn in place at 0.5 rad/s, the map growing 1 m³/s   -> turn (4 s)
//   4-14 s   fly 10 m east at 1 m/s, map growing 2 m³/s           -> new (10 s, 10 m)
//   14-16 s  hover                                                -> hover (2 s)
//   16-26 s  fly back west 10 m over the same ground, no growth   -> revisit (10 s, 10 m)
//   26-30 s  fly 4 m north, the map growing 0.5 m³/s              -> new (4 s, 4 m)
//   30-40 s  hover, then Time_f; Time_settled at 30 s             -> end game (10 s)
struct Script {
  TimeSplit split;
  double covered_m3 = 0.0;

  void run() {
    Eigen::Vector3d p(0, 0, 1);
    double yaw = 0.0;
    const double dt = 0.01;
    for (int i = 1; i <= 4000; ++i) {
      const double t = i * dt;
      double growth = 0.0;  // m³/s
      if (t <= 4.0) {
        yaw += 0.5 * dt;
        growth = 1.0;
      } else if (t <= 14.0) {
        p.x() += dt;
        growth = 2.0;
      } else if (t <= 16.0) {
      } else if (t <= 26.0) {
        p.x() -= dt;
      } else if (t <= 30.0) {
        p.y() += dt;
        growth = 0.5;
      }
      covered_m3 += growth * dt;
      split.on_pose(t, p, std::remainder(yaw, 2 * 3.14159265358979));
      split.on_covered(t, static_cast<int64_t>(std::llround(covered_m3 * 1000.0)));
    }
  }
};

TEST(TimeSplit, AScriptedRunSplitsIntoItsKnownParts) {
  Script s;
  s.run();
  const TimeSplitResult r = s.split.finish(40.0, 30.0, 1e-3);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kTurn)], 4.0, 1e-6);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kNew)], 14.0, 1e-6);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kHover)], 2.0, 1e-6);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kRevisit)], 10.0, 1e-6);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kEndGame)], 10.0, 1e-6);
  EXPECT_NEAR(r.distance_m[static_cast<size_t>(TimeUse::kNew)], 14.0, 1e-6);
  EXPECT_NEAR(r.distance_m[static_cast<size_t>(TimeUse::kRevisit)], 10.0, 1e-6);
  EXPECT_NEAR(r.distance_total_m, 24.0, 1e-6);
  EXPECT_NEAR(r.new_m3[static_cast<size_t>(TimeUse::kNew)], 22.0, 0.01);
  EXPECT_NEAR(r.share(TimeUse::kRevisit), 0.25, 1e-9);
  // The flight back (x = 26 - t) is over ground flown at least 10 s before once some earlier
  // slice end within 1 m of it is that old: the outbound leg was at x' = t' - 4, so from t = 19.5
  // s on (x <= 6.5 m), about 6.5 m of the 10 (slice ends decide, to half a metre); and the first
  // metre north of the start, where it turned 22 s before.
  EXPECT_NEAR(r.revisit_by_place_m, 7.5, 0.51);
  EXPECT_EQ(r.slices.size(), 80u);
}

TEST(TimeSplit, TheJsonListsEveryUseAndTheSliceSequence) {
  Script s;
  s.run();
  const std::string j = s.split.finish(40.0, 30.0, 1e-3).to_json();
  for (const char* k : {"\"new\"", "\"revisit\"", "\"turn\"", "\"hover\"", "\"end_game\"", "\"revisit_by_place_m\""})
    EXPECT_NE(j.find(k), std::string::npos) << k;
  // 8 turn slices, 20 new, 4 hover, 20 revisit, 8 new, 20 end game.
  const std::string seq = std::string(8, 't') + std::string(20, 'n') + std::string(4, 'h') + std::string(20, 'r') +
                          std::string(8, 'n') + std::string(20, 'e');
  EXPECT_NE(j.find("\"slices\": \"" + seq + "\""), std::string::npos) << j;
}

TEST(TimeSplit, PosesOutOfOrderOrNotFiniteAreIgnoredAndAnEmptyRunIsAllHover) {
  TimeSplit split;
  split.on_pose(1.0, Eigen::Vector3d(0, 0, 0), 0.0);
  split.on_pose(0.5, Eigen::Vector3d(100, 0, 0), 0.0);  // earlier: ignored
  split.on_pose(2.0, Eigen::Vector3d(NAN, 0, 0), 0.0);  // not finite: ignored
  split.on_pose(3.0, Eigen::Vector3d(0, 0, 0), NAN);    // no yaw: no turn
  const TimeSplitResult r = split.finish(4.0, 10.0, 1e-3);
  EXPECT_NEAR(r.distance_total_m, 0.0, 1e-12);
  EXPECT_NEAR(r.time_s[static_cast<size_t>(TimeUse::kHover)], 4.0, 1e-9);
  const TimeSplitResult none = TimeSplit().finish(0.0, 0.0, 1e-3);
  EXPECT_TRUE(none.slices.empty());
  EXPECT_EQ(none.share(TimeUse::kNew), 0.0);
}

}  // namespace
}  // namespace semx::core
