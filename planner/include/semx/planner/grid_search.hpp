// Path search over the known free space (FUEL's A* over its map, path_searching/astar2.cpp), with
// the planner's clearance, for FUEL's travel costs and paths.
//
// Two lattices over the map's voxels:
//   coarse: cells of `step` voxels (0.2 m), a cell passable when its centre is known free and the
//     ESDF there (CollisionChecker::esdf, unknown counted as obstacle) is at least door_clearance
//     less half a cell: lenient, so a doorway the vehicle fits through is never lost between two
//     cell centres (a 7-voxel gap reads 0.35 m only on its middle voxel's centre, 0.30 m at the
//     corners next to it). distances() runs Dijkstra on it: travel costs, FUEL's cost matrix.
//   fine: the voxels, passable with the clearance of a passage node (ESDF >= door_clearance).
//     find_path() runs A* on it inside a corridor around the coarse path, and shorten() makes
//     the result a polyline every segment of which passes CollisionChecker::edge_free (from the
//     vehicle: root_edge_free), the check the main loop and the controller's contract use.
// On both, a step into a cell whose ESDF is below passage_clearance costs (1 + low_penalty) times
// its length, so paths keep to the middle of rooms and cross doorways, not corridors along walls;
// diagonal steps need every cell they cut across passable. Near the search's source (within
// collision.root_escape_radius) a cell is passable when it is not occupied and the bare body box
// there touches no occupied voxel: root_edge_free's escape rule, so a vehicle whose surroundings
// are not all mapped (always at the start) can leave.
//
// Passability is cached per cell and dropped around the voxels that change (note_changes), so a
// search pays the ESDF once per cell until the map changes near it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "semx/core/radix_heap.hpp"
#include "semx/core/zero_array.hpp"
#include "semx/map/map_delta.hpp"
#include "semx/map/state_grid.hpp"
#include "semx/planner/collision_checker.hpp"
#include "semx/planner/planner_config.hpp"

namespace semx::planner {

class GridSearch {
 public:
  GridSearch(const CollisionChecker& checker, const CollisionConfig& collision, int step, double low_penalty);

  // The grid the checker reads; a different one drops every cache.
  void set_grid(const map::StateGrid* grid);
  // These voxels changed: passability near them is computed again.
  void note_changes(const std::vector<map::VoxelChange>& changes);
  void reset();

  struct Result {
    std::vector<double> distance;  // per target, m of coarse path; +inf when not reached
    int64_t settled = 0;           // cells taken off the queue
  };
  // Dijkstra over the coarse lattice from `source` until every target's cell (or a passable
  // neighbour of it) is settled or max_settled cells were; `escape`: the escape rule near the
  // source. With keep_tree the search tree stays for tree_path() (until the next keep_tree).
  Result distances(const Eigen::Vector3d& source, bool escape, const std::vector<Eigen::Vector3d>& targets,
                   int64_t max_settled, bool keep_tree);
  // The coarse path of the kept tree from its source to `target` (source and target included);
  // empty when the tree did not reach it.
  std::vector<Eigen::Vector3d> tree_path(const Eigen::Vector3d& target) const;

  // A path the vehicle at `a` can fly to `b`: A* over voxels within two coarse cells of `guide`
  // (everywhere when guide is empty), shortened. False when none was found within
  // max_expansions; `expanded` counts the voxels settled. A start that is not node_free and has
  // no way off it under the usual rules (the search runs dry within a few thousand voxels, or
  // every first segment fails edge_free) is searched again under the escape rule, as a start
  // without the clearance is.
  bool find_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::vector<Eigen::Vector3d>& guide,
                 int64_t max_expansions, std::vector<Eigen::Vector3d>& out, int64_t* expanded = nullptr);
  // Drops every point of `path` that its neighbours can be joined around with a segment that
  // passes edge_free, greedily from the start; with first > 0 (a start without the clearance) the
  // first segment goes to path[first] under root_edge_free's escape rule (checked to each point
  // up to it). False when some consecutive pair does not pass.
  bool shorten(const std::vector<Eigen::Vector3d>& path, std::vector<Eigen::Vector3d>& out, size_t first = 0) const;

  int step() const { return coarse_.stride; }
  // The body box with a small margin overlaps no occupied voxel anywhere on a-b.
  bool body_clear(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

 private:
  // find_path() once; `force_escape`: the escape rule near `a` even where its cell has the
  // clearance. `pocket` (when given), after a failure without the escape rule: the start had no
  // way off it (see find_path above), so the escape rule may find one.
  bool find_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const std::vector<Eigen::Vector3d>& guide, int64_t max_expansions,
                 std::vector<Eigen::Vector3d>& out, int64_t* expanded, bool force_escape, bool* pocket);
  // kEscape: passable only by the escape rule near the search's source (never cached).
  enum : uint8_t { kUnset = 0, kBlocked = 1, kLow = 2, kHigh = 3, kEscape = 4 };
  // A dense box of cells of `stride` voxels, with passability and the search's scratch.
  struct Lattice {
    int stride = 1;
    double threshold = 0.0;  // ESDF a passable cell needs
    map::VoxelKey origin;    // lattice coordinates of index 0
    int nx = 0, ny = 0, nz = 0;
    // Zero-filled on first touch (core/zero_array.hpp): the box spans the known map, a search
    // touches a corridor of it, and a growth of the box writes only the cached cells it keeps.
    // cls starts kUnset (0); g and parent are read only where stamp says this search wrote them.
    core::ZeroArray<uint8_t> cls;
    core::ZeroArray<float> g;
    core::ZeroArray<int32_t> parent;
    core::ZeroArray<uint32_t> stamp;   // g and parent hold for this search when == now
    core::ZeroArray<uint32_t> closed;  // settled in this search when == now
    uint32_t now = 0;
    // Per column (x, y) of the coarse lattice: the heights (bit z) it is passable at, and at which
    // of them the clearance is passage_clearance; and the column search's scratch.
    core::ZeroArray<uint8_t> col_set;
    core::ZeroArray<uint64_t> col_pass, col_high;
    core::ZeroArray<float> col_g;
    core::ZeroArray<int32_t> col_parent;
    core::ZeroArray<uint32_t> col_stamp, col_closed;
    int64_t index(const map::VoxelKey& l) const;
    map::VoxelKey coords(int64_t i) const;
  };
  map::VoxelKey lattice_of(const Lattice& l, const Eigen::Vector3d& p) const;
  Eigen::Vector3d point(const Lattice& l, const map::VoxelKey& c) const;
  // The grid's known box (padded) fits in the lattice; pending changes are applied.
  void prepare(Lattice& l);
  // A changed 4^3 cube of voxels: the cells near it are computed again, all of them when a
  // change there may have lowered the ESDF (lowers), else all but the kHigh ones.
  void invalidate(Lattice& l, const map::VoxelKey& cube, bool lowers);
  uint8_t cls(Lattice& l, int64_t i);
  // Passability with the escape zone around `source` (when escape).
  uint8_t passable(Lattice& l, int64_t i, const Eigen::Vector3d& source, bool escape);
  // Dijkstra (A* toward `goal` when goal_index >= 0) on l from the seeded cells; goal_index and
  // open_index (-1: none) count as passable whatever their class; allowed(coords) restricts the
  // cells; settle(index) returns true to stop. Returns the cells settled.
  template <class Allowed, class Settle>
  int64_t search(Lattice& l, const std::vector<std::pair<int64_t, double>>& seeds,
                 const Eigen::Vector3d& source, bool escape, int64_t goal_index, int64_t open_index,
                 const Eigen::Vector3d& goal, int64_t max_settled, Allowed&& allowed, Settle&& settle);
  // A coarse column's passable heights and those with passage clearance (cached).
  void column(int64_t col, uint64_t& pass, uint64_t& high);
  // The cells that stand for p: its own and its 26 neighbours.
  std::vector<int64_t> cells_near(const Lattice& l, const Eigen::Vector3d& p) const;

  const CollisionChecker& checker_;
  CollisionConfig collision_;
  double low_penalty_;
  const map::StateGrid* grid_ = nullptr;
  Lattice coarse_, fine_;
  // 4^3 cubes changed since each lattice looked, each with whether a change there may have
  // lowered the ESDF (a voxel that stopped being free, or whose previous state is not known).
  std::map<map::VoxelKey, bool> dirty_coarse_, dirty_fine_;
  std::unordered_map<int64_t, uint8_t> escape_cache_;  // this search's escape-zone answers
  core::RadixHeap column_queue_;                       // distances()' queue, its memory kept
  // The kept tree: its source, and the coarse lattice's g and parent when it was searched.
  bool tree_valid_ = false;
  Eigen::Vector3d tree_source_ = Eigen::Vector3d::Zero();
  std::vector<float> tree_g_;
  std::vector<int32_t> tree_parent_;
  map::VoxelKey tree_origin_;
  int tree_nx_ = 0, tree_ny_ = 0;
};

}  // namespace semx::planner
