// The planner's clearance and the controller's are the same quantity: whatever edge the planner
// accepts, the controller's ESDF (the mapper's field, read through GridDistanceField) keeps the
// controller's bound plus its sampling pad at every point of it, so the polyline itself is a
// trajectory the controller accepts. Checked on doorways 6-10 voxels wide (0.9-1.0 m doors
// become 7-10 in the map when the jambs land on voxel boundaries).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "planner_test_util.hpp"
#include "semx/controller/controller_config.hpp"
#include "semx/controller/grid_distance_field.hpp"
#include "semx/mapper/esdf_builder.hpp"
#include "semx/planner/collision_checker.hpp"

namespace semx::planner {
namespace {

using map::VoxelState;

// A room 6 x 4 x 2.5 m split at y = 2.0..2.2 by a wall with a doorway `voxels` wide from x = 3.0.
map::StateGrid doorway_map(int voxels) {
  map::StateGrid g = SyntheticWorld::room({6, 4, 2.5}, {1, 1, 1.2}).full_map();
  fill_m(g, {0, 2.0, 0}, {6, 2.2, 2.5}, VoxelState::kOccupied);
  fill_m(g, {3.0, 2.0, 0.1}, {3.0 + 0.1 * voxels, 2.2, 2.1}, VoxelState::kFree);
  return g;
}

controller::GridDistanceField controller_field(const map::StateGrid& g) {
  mapper::EsdfParams p;
  p.window = {8.0, 6.0, 4.0};
  p.unknown_as_occupied = false;  // as the demo runs it: the planner is the stricter one
  mapper::EsdfBuilder b(p, g.resolution());
  b.update(g, {3, 2, 1.2}, map::KeyBox{}, 1, true);
  const map::EsdfGrid& e = b.grid();
  return controller::GridDistanceField(e.origin_point(), e.resolution, e.nx, e.ny, e.nz, e.distance,
                                       p.max_distance, controller::OutsideWindow::kFree);
}

TEST(ClearanceConsistency, PlannerEsdfIsTheControllersField) {
  const map::StateGrid g = doorway_map(9);
  const controller::GridDistanceField f = controller_field(g);
  CollisionChecker c(CollisionConfig{});
  c.set_grid(&g);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(0.3, 5.7), y(0.3, 3.7), z(0.3, 2.2);
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d p(x(rng), y(rng), z(rng));
    const double cap = 0.6, mine = c.esdf(p, cap), theirs = f.distance(p);
    // Exact below the cap (up to the float the field stores), never above the controller's.
    if (theirs < cap) {
      EXPECT_NEAR(mine, theirs, 1e-5) << p.transpose();
    } else {
      EXPECT_GE(mine, cap) << p.transpose();
    }
    EXPECT_LE(mine, theirs + 1e-5) << p.transpose();
  }
}

TEST(ClearanceConsistency, AcceptedEdgesKeepTheControllersBound) {
  const controller::ControllerConfig cc;
  CollisionConfig cfg;
  for (int voxels : {6, 7, 8, 9, 10}) {
    const map::StateGrid g = doorway_map(voxels);
    const controller::GridDistanceField f = controller_field(g);
    // What the controller requires of every dense sample of a new trajectory (clearance.cpp).
    const double need = cc.clearance.bound() + 0.5 * f.lipschitz() * cc.clearance.check_spacing;
    EXPECT_LE(need, cfg.door_clearance + 1e-12);
    CollisionChecker c(cfg);
    c.set_grid(&g);
    const double mid = 3.0 + 0.05 * voxels;
    std::mt19937 rng(voxels);
    std::uniform_real_distribution<double> dx(-0.6, 0.6), dz(-0.3, 0.3);
    int accepted = 0;
    for (int i = 0; i < 400; ++i) {
      // Straight crossings (the middle tried exactly too) and slanted ones.
      const double ox = i == 0 ? 0.0 : dx(rng), oz = i == 0 ? 0.0 : dz(rng);
      const double slant = i % 2 ? 0.0 : 0.3 * dx(rng);
      const Eigen::Vector3d a(mid + ox + slant, 0.9, 1.2 + oz), b(mid + ox - slant, 3.3, 1.2 + oz);
      if (!c.edge_free(a, b)) continue;
      ++accepted;
      double low = 1e9, below = 0.0;
      const double dt = 1e-4, len = (b - a).norm();
      for (double t = 0; t <= 1.0; t += dt) {
        const double d = f.distance(a + t * (b - a));
        low = std::min(low, d);
        if (d < cfg.passage_clearance) below += dt * len;
      }
      EXPECT_GE(low, need) << voxels << " voxels: " << a.transpose() << " -> " << b.transpose();
      // Closer than passage_clearance only for a doorway's crossing.
      EXPECT_LE(below, cfg.door_length + 0.01) << voxels;
    }
    // The ESDF peaks at 0.25 m in a 6-voxel gap (no path), 0.35 m in 7-8 and 0.45 m in 9-10.
    if (voxels == 6) {
      EXPECT_EQ(accepted, 0);
    } else {
      EXPECT_GT(accepted, 0) << voxels;
    }
    // A passage node centred from a draw off the middle lands where edges through it exist.
    Eigen::Vector3d p(mid + 0.12, 2.1, 1.2);
    if (voxels > 6) {
      EXPECT_TRUE(c.centre(p, 3, 0.3, true)) << voxels;
      EXPECT_GE(f.distance(p), need);
    }
  }
}

TEST(ClearanceConsistency, NoLongFlightAlongAWallBelowPassageClearance) {
  // A wall along x at y = 2.0..2.2; an edge parallel to it at 0.40 m ESDF is refused even though
  // it keeps door_clearance: that is for doorways only.
  const map::StateGrid g = doorway_map(0);
  CollisionChecker c(CollisionConfig{});
  c.set_grid(&g);
  EXPECT_FALSE(c.edge_free({1.0, 1.6, 1.2}, {5.0, 1.6, 1.2}));
  EXPECT_TRUE(c.edge_free({1.0, 1.5, 1.2}, {5.0, 1.5, 1.2}));
}

}  // namespace
}  // namespace semx::planner
