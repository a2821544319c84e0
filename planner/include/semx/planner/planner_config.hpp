// Every parameter of the planner, with its default. This struct is the one place defaults are set;
// docs/planner.md and planner/config/planner.yaml mirror it (a test loads the YAML file and
// compares it with these defaults).
//
// YAML layout: top-level `planner`, `seed`, `rate_hz`, then one mapping per struct below, keys
// named as the fields (vectors as YAML sequences).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "semx/runtime/config.hpp"

namespace semx::planner {

// The four planners of the paper's comparison (DESIGN.md §4), FUEL as a later baseline, and a
// reference that cheats.
enum class PlannerKind {
  kSemanticDep,  // DEP roadmap + semantic reward (the paper's method)
  kDep,          // the same roadmap, semantics off
  kNbv,          // receding-horizon RRT next-best-view (Bircher 2016)
  kAep,          // RRT* with cached gains and frontier fallback (Selin 2019)
  kFuel,         // frontier clusters, a global tour over their viewpoints (Zhou 2021)
  // DEP's roadmap with what the semantic map says about rooms: a door region is a room's
  // boundary, and the rules of RoomConfig order the goals by room (semantic_room_strategy.hpp).
  kSemanticRoom,
  // FUEL's frontier-cluster tour with what the semantic map says about rooms: a leg that passes a
  // door costs extra, so the tour finishes a room before it crosses a door
  // (semantic_fuel_strategy.hpp).
  kSemanticFuel,
  // NOT an exploration method: reads the world's ground truth and flies a precomputed tour of
  // viewpoints that sees it (oracle_strategy.hpp), the physical-limit reference of the bench.
  kOracle,
};
const char* to_string(PlannerKind k);
// Throws std::invalid_argument for an unknown name.
PlannerKind parse_planner_kind(const std::string& name);

// The vehicle and how far paths keep from what is not known to be free (CollisionChecker).
struct CollisionConfig {
  Eigen::Vector3d vehicle_size{0.5, 0.5, 0.3};  // m, body box (x, y, z)
  double margin = 0.1;                          // m, added to each half size of the body box
  // m: ESDF distance every node keeps from occupied and unknown voxels, measured as the controller
  // measures it (CollisionChecker::esdf: voxel-centre distances minus half a voxel, trilinear). A
  // goal is where the vehicle hovers and starts its next path, so it keeps more than the
  // controller's bound (half_size 0.25 + margin 0.07, plus its 0.017 m sampling pad).
  double clearance = 0.45;
  // m: the same for every point the vehicle only passes through: every point of an edge (not
  // only its samples) and passage nodes (nodes in a gap too narrow for `clearance`, never goals).
  // >= the controller's bound 0.32 plus its pad 0.5 * sqrt(3) * 0.02 with room to spare (the
  // body turned 45° reaches 0.354 m), so any path the planner emits passes the controller's check
  // as a polyline. Nodes and edges away from doorways keep this.
  double passage_clearance = 0.42;
  // m: in doorways, less: at most door_length of an edge and passage nodes may come down to this.
  // A 0.9-1.0 m door mapped 7-8 voxels wide has an ESDF of 0.35 m in its middle (trilinear
  // between voxel centres; flat over the middle 0.1 m of an 8-voxel gap); 0.34 plus the fine
  // check's excess (|u|_1 * kFineStep / 2 = 0.005 straight across) fits under it, and is >= the
  // controller's bound (half_size 0.25 + margin 0.07) plus its pad 0.017. Only in doorways: flying
  // along a wall at 0.34 m with the body turned 45° (half diagonal 0.354 m) leaves nothing when
  // the wall's surface is the mapped voxel face.
  double door_clearance = 0.34;
  // m: a crossing of a 0.2 m wall sees < passage_clearance for ~0.7 m; env2's 1.5 m passage
  // takes passage nodes inside.
  double door_length = 1.0;
  // m: edges are checked at points this far apart, each vouching for the stretch around it
  // (CollisionChecker::samples_free); where one falls short, points kFineStep apart decide.
  double edge_step = 0.1;
  // m: near the vehicle an edge from the root is checked only against occupied voxels and the
  // bare vehicle box, so the vehicle can leave a pose whose surroundings are not mapped yet.
  double root_escape_radius = 1.0;
};

// Where candidate nodes are drawn.
struct SamplingConfig {
  int samples = 45;  // candidates kept per cycle at most: the paper's sampling density
  // Candidates per cycle drawn between unreachable roadmap parts and the reachable one (through
  // the doorway between them; DepStrategy::bridge); 0 disables.
  int bridge_attempts = 20;
  int max_attempts_factor = 4;     // candidates collision-checked per cycle at most samples × this
  int max_draws_factor = 25;       // draws at most samples × max_attempts_factor × this (a draw whose
                                   // voxel is not free is dropped before any check)
  double local_radius = 5.0;       // m, horizontal half width of the box around the vehicle
  double local_height = 1.0;       // m, vertical half height of that box
  double frontier_fraction = 0.4;  // share of draws around frontier clusters (anywhere)
  double frontier_radius = 1.5;    // m, half width of the box drawn around a frontier cluster
  double min_node_distance = 0.5;  // m, a candidate closer than this to a node is dropped
  double z_min = 0.3;              // m, absolute limits of node heights
  double z_max = 3.0;
  double cluster_size = 1.0;   // m, edge of the cells frontier voxels are grouped in
  int min_cluster_voxels = 3;  // frontier voxels a cell needs to attract samples
};

struct RoadmapConfig {
  int k_nearest = 8;             // a new node is connected to at most this many nearest nodes
  double max_edge_length = 2.5;  // m
};

// The sensor model of the gain and the gain's weights.
struct GainConfig {
  // Camera (DESIGN.md §5: 90° horizontal, fx = fy = 320 at 640 × 480): the frustum's horizontal
  // and vertical field of view come from these.
  int image_width = 640;
  int image_height = 480;
  double fx = 320.0;
  double fy = 320.0;
  double min_range = 0.5;  // m
  double max_range = 5.0;  // m
  // G = w_unknown U_n + w_frontier U_f + w_surface U_s (DEP's 1, 2, 4).
  double weight_unknown = 1.0;
  double weight_frontier = 2.0;
  double weight_surface = 4.0;
  int yaw_bins = 32;         // azimuth histogram (DEP)
  int rays_azimuth = 128;    // gain rays around the node (a multiple of yaw_bins)
  int rays_elevation = 10;   // rays across the vertical field of view
  double min_gain = 1000.0;  // a node with G below this is not a goal (weighted voxels)
  // An ablation (docs/planner.md, "Gain"): DEP's score counts what the turn to a node's yaw
  // sweeps, not only the final window, and takes the yaw that scores best that way. false (the
  // default): the best window's gain and yaw, DEP's definition. Eligibility (min_gain) and
  // termination use the best window either way.
  bool sweep = false;
  // Unknown space does not occlude (DEP's optimistic assumption), except behind a surface voxel
  // (unknown, next to free and to occupied space): a ray that reaches one counts it and stops,
  // because what lies behind an object's unseen surface is mostly the object's inside, which no
  // view observes (docs/planner.md, "The end game"). false: DEP's model, every unknown voxel up to
  // the first occupied one counts.
  bool surface_occludes = false;

  double horizontal_fov() const;  // rad
  double vertical_fov() const;    // rad
};

struct CostConfig {
  double velocity = 1.0;    // m/s, v of T = d/v + w_psi Δψ/ω
  double yaw_rate = 1.0;    // rad/s, ω
  double yaw_weight = 1.0;  // w_psi
  double min_time = 0.5;    // s, T is at least this, so a node next to the vehicle scores finitely
  // The controller flies position and heading as one trajectory, so a path that moves and turns
  // takes the longer of d/v and w_psi Δψ/ω, not their sum (the paper's Eq. 8). The sum counts a
  // turn made on the way as time lost and steers DEP toward goals straight ahead; with the
  // longer of the two, 85 % coverage came 18-23 % earlier in env2 and env3 over ten seeds
  // (docs/planner.md, "Travel cost and score"). false: the paper's sum.
  bool turn_while_flying = true;
  // m of path: while any eligible node lies within this path distance of the vehicle, DEP
  // chooses among those only (best score first) and looks farther only once they are done, so
  // small leftovers near the vehicle are finished before it leaves them behind (the end game:
  // docs/planner.md). 0: the paper's rule, the best score anywhere.
  double local_first = 0.0;
  // e of Score = (G + R_sem) / T_path^e. Below 1 a large gain farther away outranks the small
  // leftovers next to the vehicle more readily (the oracle's greedy walks use 0.5 and 1; docs/planner.md,
  // "Travel cost and score"). 1: the paper's score.
  double time_exponent = 1.0;
};

// The semantic reward R_sem (semantic_reward.hpp); only semantic-dep uses it.
struct RewardConfig {
  // κ, per weighted voxel: region i rewards w_i (1 - d_i / r_i) (1 + κ U_i), where U_i is the
  // gain over every yaw (weighted unknown voxels in view all round) of the roadmap node nearest
  // its centroid. An object whose surroundings are still unexplored marks a room not yet seen
  // and draws the vehicle there; one in a mapped room rewards what the paper's Eq. 6 gives.
  // 0: the paper's reward.
  double unexplored_weight = 0.0;
  // κ_p, per weighted voxel, for door regions only: a door rewards w_i (1 - d_i / r_i)
  // (a_i + κ_p U_i), a_i = 1 while the region is active and 0 once the leaf is fully observed,
  // U_i as above. A doorway is a passage: what matters is the unknown volume around it (the room
  // behind), not whether the leaf itself was seen, so the term outlives the leaf's observation
  // and fades as the room is mapped. 0: the paper's reward.
  double passage_weight = 0.0;
  // An ablation: a region rewards a node only when its centroid lies in the camera's horizontal
  // field of view at the node's yaw (docs/planner.md, "Semantic reward"). false: the paper's
  // Eq. 6, every region within r_i whichever way the node looks.
  bool in_view = false;
};

// semantic-room (semantic_room_strategy.hpp; docs/planner.md, "semantic-room"): DEP whose goals
// are ordered by the rooms the semantic map shows. Rooms: the roadmap split at its doorways,
// i.e. at the nodes within door_radius of a door region (semantics) and, with passages_bound, at
// the passage nodes DEP centres in gaps too narrow for a node (geometry).
struct RoomConfig {
  double door_radius = 1.0;  // m, horizontal: nodes this near a door region's centroid stand in its doorway
  bool passages_bound = true;
  // Weighted voxels: while a node of the vehicle's room has at least this gain, nodes beyond its
  // doorways are not chosen (finish the room before passing a door); 0: off.
  double finish_gain = 3000.0;
  // A global order of rooms: the rooms with a node of finish_gain are visited in the order of the
  // shortest open tour through them from the vehicle (roadmap distances between each room's best
  // node; tour_solver.hpp), and only the first room's nodes of finish_gain are goals while any
  // is left. false: the vehicle's own room first, then DEP's ranking.
  bool tour = false;
  // What "gain left in the room" counts: false, G itself; true, only its frontier and surface
  // voxels (w_f U_f + w_s U_s at the best window). G counts unknown space behind walls too (unknown
  // does not occlude), so next to an unexplored room a room's nodes keep a large G that staying
  // in the room never lowers; its frontier and surface voxels are what looking around it shows.
  bool boundary_gain = false;
  // The paper's Eq. 6 reward on top (as semantic-dep); false: G / T_path alone.
  bool eq6_reward = true;
  // Look into a room before entering it: a node in a room other than the vehicle's is scored
  // with its path from the vehicle plus this times its depth beyond the room's doorway (the path
  // length past the nearest doorway node next to the room), the way back out that a look from
  // the doorway saves. A dead-end room entered early is flown twice before 85 %; 0: off. The main
  // loop's switch test (hysteresis) re-scores the flown goal without it: a goal once chosen in
  // another room is not given up for the way back it was charged.
  double return_weight = 0.0;
  // An edge that passes within door_radius (horizontally) of a door region's centroid is cut too:
  // edges are up to roadmap.max_edge_length long, so one can join the nodes on both sides of a
  // doorway past the nodes that stand in it, and the two rooms would be one.
  bool cut_edges = false;
  // return_weight only for rooms with one way in known (one door or passage next to them): a room
  // with a second door is flown through, not left the way it was entered.
  bool dead_ends_only = false;
};

// semantic-fuel (semantic_fuel_strategy.hpp; docs/planner.md, "semantic-fuel"): FUEL's tour with
// what the semantic map knows. Rooms: a site's room is the last door region its coarse path from
// the vehicle passes within door_radius of (none: the vehicle's room).
struct SemanticFuelConfig {
  double door_radius = 1.0;  // m, horizontal (and within door_height vertically)
  double door_height = 1.5;  // m
  // s added to a tour leg that changes room (and to the first leg into another room): the tour
  // then changes room as few times as it can; 0: FUEL's tour.
  double door_cost = 0.0;
  // Object pockets: a frontier cluster too small for FUEL's tour (below fuel.major_cluster_voxels
  // or fuel.major_coverage) whose mean lies within object_margin of the box of an object region not
  // yet fully observed (centroid and extent) is toured with the large clusters, while the vehicle
  // is in its room, instead of after all of them. false: FUEL's order.
  bool object_pockets = true;
  double object_margin = 0.5;  // m
  // ... and only while the cluster's mean is within this of the vehicle (m; 0: wherever it is):
  // pockets are taken on the way, not flown to across the room.
  double object_reach = 0.0;
  // Turns in place at the start (each 2 pi / start_turns), before the first tour: DEP's first
  // goals look around the start, FUEL's fly to the nearest cluster. 0: FUEL's start.
  int start_turns = 0;
  // Doorways first: a door region means a room behind it. While a cluster lies within
  // doorway_radius (horizontally) of a door region, the tour's first leg into any other cluster
  // costs doorway_first_cost s more, so the vehicle looks into the room behind a door before it
  // finishes what is around it. 0: off.
  double doorway_first_cost = 0.0;
  double doorway_radius = 1.5;  // m
  // Doorway clusters: a frontier cluster too small for FUEL's tour whose mean lies within
  // doorway_radius of a door region is toured with the large ones: a doorway's frontier is small,
  // the room behind it is not. false: FUEL's order.
  bool door_clusters = false;
  // Not semantic: DEP's goals (its roadmap, G / T) for the first dep_first_s seconds, FUEL's tour
  // after (DEP reaches 85 % of small worlds sooner, FUEL of large ones). 0: off.
  double dep_first_s = 0.0;
  // Semantic: DEP's goals until the semantic map has shown tour_doors doors (regions of the door
  // class, one per door_radius), FUEL's tour for good after. A door means a room behind it: with
  // one way onward there is nothing to order and DEP's greedy look around sees the rooms soonest
  // (it reaches 85 % of worlds of one to three rooms sooner than any tour tried); with several
  // rooms known the tour's global order pays. 0: off.
  int tour_doors = 0;
  // Not semantic: whenever FUEL's tour picks its next goal, DEP's best goal is flown instead when
  // its G / T is greedy_ratio times that of the tour's goal, both in DEP's measure (the volumetric
  // gain in the goal's yaw window over the travel time): the tour sees frontier clusters, and a
  // doorway's is small while the room behind it is not. DEP's goal is flown until it is reached
  // or no longer informative. 0: off.
  double greedy_ratio = 0.0;
  // With fuel.latency_tour: what an object not yet fully observed is worth in the tour's order. A
  // site's weight (its coverage) is multiplied by 1 + object_weight × the share of its cluster's
  // voxels within object_margin of such an object's box, so the tour sees the unseen sides of
  // objects sooner without touring anything it would not. Negative (down to -1): the other way,
  // the frontier at an unfinished object is a detail of it (the space under a table, behind a
  // cabinet), left for after the rooms. 0: the latency tour's weights.
  double object_weight = 0.0;
  // ... and a door region means a room behind it: a site whose cluster's mean lies within
  // doorway_radius of a door weighs 1 + door_weight times its coverage. 0: off.
  double door_weight = 0.0;
  // ... counting only doors with a room behind them still to see: at least door_open_share of the
  // voxels within door_probe_radius of the door's centroid (a disc at its height) unknown. A door
  // leaf is seen from both rooms, and once both are mapped its doorway leads nowhere new (every
  // door counted, door_weight lost: docs/planner.md). 0: every door.
  double door_open_share = 0.0;
  double door_probe_radius = 2.0;  // m
};

// The main loop: when to replan, when to give up.
struct LoopConfig {
  double goal_tolerance = 0.3;  // m, the goal counts as reached within this
  double yaw_tolerance = 0.3;   // rad, a turn smaller than this is no reason to move
  double dwell_s = 0.3;         // s within tolerance before the goal counts as reached
  double hysteresis = 1.5;      // switch goals only for a score this many times better
  int done_cycles = 5;          // consecutive cycles without any goal before DONE
  // ... or this many when informative roadmap nodes exist that the vehicle cannot reach (the
  // recovery sampling may reconnect them).
  int max_recovery_cycles = 40;
  // DEP-family recovery: when informative nodes are cut off and relinking has not joined them
  // for cut_look_cycles cycles, fly to the reachable node nearest an unreachable one across open
  // space (no occupied voxel on the line between them) and look across the cut, at most
  // cut_looks times between two real goals and never twice from one place (1 m). Depth noise
  // maps a doorway's jambs a voxel too wide after the vehicle has passed, and only the camera
  // clears them (the 396 m² world of the 24-world set with noise: DONE at 96.6 % with 950
  // informative nodes behind a doorway mapped 0.7 m wide; docs/planner.md "A look across the
  // cut"). 0: off.
  int cut_looks = 4;
  int cut_look_cycles = 8;
  int cut_look_nodes = 10;    // informative nodes a part cut off must hold to be looked at
  int blacklist_cycles = 20;  // a goal the controller rejected is skipped this long
  // A goal just reached is skipped this long: what its gain still counts after the vehicle stood
  // there and looked is what the camera could not see (sensor-model mismatch), not a reason to
  // come back at once.
  int visited_cycles = 40;
  double max_start_offset = 0.6;  // m, a pending path whose start the vehicle left is dropped
  // s the controller may HOLD the path's end with the vehicle farther than goal_tolerance from the
  // goal before the goal is given up (and blacklisted): a vehicle that cannot get there (its
  // commands rejected, a body that does not fit) would otherwise wait for it forever.
  double short_hold_s = 3.0;
  // s after a path went out: a controller that still reports no plan at all has lost it (it was
  // restarted after a crash), and the planner plans again. In a run without a restart a
  // controller never reports plan 0 once it has taken a path, so this changes nothing there.
  double lost_path_s = 1.0;
  // Goals that do not deliver (docs/planner.md, "The end game"): the share of their gain that the
  // last this many goals delivered (voxels the map gained while each was flown, over the gain it
  // was chosen with; at most 1) scales every node's gain before min_gain is applied, so when the
  // gains left stop turning into map the planner ends instead of touring them. 0: off.
  int yield_goals = 0;
  // The end game of DEP and semantic-dep (docs/planner.md, "The end game"): once no reachable
  // node's gain reaches this (weighted voxels, the units of gain.min_gain), only pockets are left
  // (under tables, on cabinets), and the goal is the first stop of the shortest tour through all
  // of them instead of the best G/T, held until it is reached or no longer informative. 0: off
  // (greedy to the end).
  double end_game_gain = 0.0;
  double end_game_site_spacing = 1.0;  // m: informative nodes this near a stronger one are one stop
  int end_game_max_sites = 48;         // stops of the tour at most (the most informative)
  // Pockets before a far goal (DEP and semantic-dep, after the score: docs/planner.md, "The end
  // game"): when the goal the score chose is far, the informative nodes (gain >= min_gain) that a
  // tour from the vehicle through them to that goal reaches with at most this fraction of the
  // direct trip's time added are visited first, in the order of the shortest such tour, each held
  // until reached or no longer informative. Pockets under tables and on cabinets that lose to a
  // far room's gain are collected while the vehicle is in their room instead of fetched one by
  // one at the end. 0: off (the score's goal).
  double pocket_detour = 0.0;
  int pocket_max_sites = 8;  // pockets considered per cycle at most (the cheapest detours, one per site)
  // Which informative nodes are pockets. true: only those left behind, i.e. nearer (by path) the
  // vehicle than the far goal and not seen in passing (within end_game_site_spacing of the way
  // with the best window looking along it). false: every informative node whose detour fits,
  // also those on the way (the vehicle stops and looks there on its way to the far goal).
  bool pocket_left_behind = false;
  // Gain evaluations DEP and semantic-dep make per cycle at most while a goal is flown (of nodes
  // new this cycle, oldest first, then the lazy ranking's re-evaluations of stale gains): the
  // ranking that asks "is there a better goal than the one flown?" then takes the best node whose
  // gain is fresh; new nodes left wait for the next cycle, and the stale ones left at the top are
  // refreshed first then. A cycle that must choose a goal (none, or reached) evaluates all it
  // needs. It bounds the cycle's CPU in large worlds, where the map changes near the vehicle
  // re-stale tens of nodes a cycle, and costs exploration speed (docs/planner.md, "Performance").
  // 0: no bound.
  int flying_refresh = 0;
};

// The deterministic charge for planning time (docs/planner.md, "Planning time").
struct ChargeConfig {
  double base_s = 0.0;  // per cycle
  // s, no cycle is charged less: its inputs, outputs and scheduling take time the fit leaves out
  // (as the mapper's streaming.lockstep_delay), and a LOCKSTEP node runs the cycle after acking
  // its tick while the clock goes on this far (docs/planner.md, "Planning time").
  double min_s = 0.1;
  double per_box_check_s = 5.0e-7;  // per vehicle-box collision check (nodes and edge samples)
  double per_gain_node_s = 0.0;     // per gain evaluation
  double per_ray_step_s = 7.0e-9;   // per voxel stepped by a gain ray
  double per_search_node_s = 0.0;   // per node settled by the graph search
  double scale = 1.0;               // multiplies everything (0: planning is free)
};

// Receding-horizon NBV (Bircher 2016).
struct NbvConfig {
  double step = 1.0;    // m, RRT extension step (the first edge is what is flown)
  double lambda = 0.5;  // 1/m, branch value Σ gain·exp(-λ·cost)
  double radius = 5.0;  // m, half width of the sampling box around the vehicle
};

// AEP (Selin 2019).
struct AepConfig {
  double step = 1.0;           // m, RRT* extension step
  double rewire_radius = 1.5;  // m
  double lambda = 0.5;         // 1/m
  double radius = 5.0;         // m, local sampling box half width
  double cache_radius = 0.3;   // m, a cached gain this close to a tree node is reused
  // Local gain below this triggers the frontier fallback. Below gain.min_gain it has no effect (a
  // local goal needs min_gain anyway), so it defaults to the same 1000.
  double g_zero = 1000.0;
  // Tree nodes grown per cycle: at least init_nodes, then more while no node's gain reaches
  // g_zero, up to max_nodes; 0 is sampling.samples (init_nodes) and init_nodes (max_nodes).
  // AEP's own code grows 15 and at most 30 (aeplanner's expandRRT, initial_iterations and
  // cutoff_iterations); the defaults grow DEP's sampling density, as in the paper's comparison:
  // with 15/30 the cycle took half the time in a 600 m² world, but Time_r came 20 s later over
  // 33 runs (docs/planner.md, "AEP's own tree size").
  int init_nodes = 0;
  int max_nodes = 0;
};

// FUEL (Zhou et al., RA-L 2021; fuel_strategy.hpp). The defaults are FUEL's own
// (exploration_manager/launch/algorithm.xml) where this map allows them; docs/planner.md, "FUEL",
// says where and why they differ.
struct FuelConfig {
  // Frontier voxels a connected group needs to be a cluster (and to be visited at all).
  int min_cluster_voxels = 30;
  // While any cluster has major_cluster_voxels voxels and a viewpoint that sees major_coverage of
  // them, the tour visits only such clusters: FUEL's own thresholds (cluster_min 100 cells,
  // min_visib_num 15 cells of 0.3 m), below which FUEL drops a cluster for good. Smaller ones are
  // visited after them, so the end of the exploration covers what the other planners cover
  // (docs/planner.md, "FUEL").
  int major_cluster_voxels = 100;
  double major_coverage = 100.0;
  // m: frontier voxels with a centre below this height are not clustered (FUEL's expandFrontier
  // drops cells below 0.4 m as noise close to the ground).
  double min_frontier_z = 0.4;
  // m: a cluster with a voxel farther than this horizontally from its mean is split in two along
  // its principal axis (FUEL's cluster_size_xy), so one viewpoint can see most of it.
  double split_radius = 2.0;
  // Viewpoint candidates on circles around a cluster's mean (FUEL's candidate_rmin, rmax, rnum,
  // dphi): radii from view_radius_min to view_radius_max in view_radius_steps steps, and
  // view_angles directions on each.
  double view_radius_min = 1.5;  // m
  double view_radius_max = 2.5;  // m
  int view_radius_steps = 3;
  int view_angles = 24;
  // m: candidates are at the cluster's mean height (clamped to sampling.z_min..z_max); when none
  // of them is a viewpoint, also this far above and below it.
  double view_height_step = 0.5;
  // When the tour finds no cluster with a viewpoint, the clusters of major_cluster_voxels and more
  // with none on the rings above (nor at a half and a quarter of the least radius) get rings
  // farther out, in view_radius steps, to the camera's range, before the planner ends (not in
  // FUEL).
  bool far_rings = true;
  // No A* path to the tour's next view while the coarse lattice has one: fly as far along the
  // coarse path as A* reaches, looking along it, at most three times per view, before it is
  // skipped (FuelStrategy::approach).
  bool approach = true;
  // At most this many of a cluster's voxels (spread over it) are tested for visibility; a
  // candidate's coverage is the share of them it sees times the cluster's voxels (FUEL
  // down-samples its cells by 3 per axis).
  int coverage_cells = 32;
  // Voxels of the cluster a candidate must see (in the camera's field of view, a line of sight
  // through known free voxels) to be a viewpoint (FUEL's min_visib_num).
  double min_coverage = 10.0;
  // A viewpoint nearer than this to the vehicle is not a cluster's tour representative while
  // another is (FUEL's min_candidate_dist).
  double min_view_distance = 0.75;  // m
  // s per rad: the first leg of a tour costs this much more per radian between the vehicle's
  // velocity and the direction to its viewpoint (FUEL's w_dir, motion consistency), so a replan
  // does not turn the vehicle back for a target about as cheap as the one ahead.
  double direction_weight = 1.5;
  // Local refinement (FUEL's refined_num, refined_radius, top_view_num, max_decay): the first
  // refine_clusters clusters of the tour, up to the first beyond refine_radius (at least two),
  // each choosing among its top_views viewpoints with coverage above max_decay x its best.
  int refine_clusters = 7;
  double refine_radius = 5.0;  // m
  int top_views = 15;
  double max_decay = 0.8;
  // Tours over at most this many clusters are solved exactly (dynamic programming); larger ones
  // by nearest neighbour, 2-opt and Or-opt (FUEL calls LKH).
  int exact_tour_max = 11;
  // Replan when this share of the target cluster's voxels is no longer frontier (FUEL's
  // min_view_finish_fraction), and every replan_period s of message time (FUEL's
  // thresh_replan3), then switching target only for a tour this much cheaper than keeping it.
  double covered_fraction = 0.2;
  double replan_period = 1.5;  // s, 0: no periodic replan
  double switch_margin = 0.1;
  // Not FUEL's (false: its shortest tour): order the tour's clusters for the time at which their
  // frontier is seen, not for the tour's length: the order of least sum of each viewpoint's
  // coverage times its arrival time (a weighted minimum-latency tour), found by Or-opt and 2-opt
  // moves from the shortest tour, at most latency_evaluations orders judged. A shortest tour may
  // leave the largest cluster for last; 85 % and 95 % come from the large ones.
  bool latency_tour = false;
  int latency_evaluations = 3000;
  // The latency tour's weight of a site: false, what its representative viewpoint covers of the
  // cluster's frontier; true, the volumetric gain G from there in its yaw window (DEP's measure:
  // the unknown space a visit reveals, which a room behind a small doorway frontier has much of).
  bool latency_gain = false;
  // The latency weight is G raised to this power (latency_gain only): above 1 the sites that look
  // into space not seen yet (a room behind its door) go before the details near the vehicle.
  double latency_gain_power = 1.0;
  // The latency tour's first site is the one of the highest rate, its weight over the first leg's
  // time (what DEP maximises), the rest in the latency order after it: DEP reaches 85 % of env3
  // flying 28 % less than the latency tour, which crosses mapped space to the site its global
  // order puts first (docs/planner.md). false: the latency order from the first site.
  bool rate_first = false;
  // latency_tour: the order is judged on the time to a share of the tour's weight as well, what
  // the known-map oracle judged on Time_r alone does (46.8 s to 85 % of env3 against 69.2 s judged
  // on both times): cost = weighted latency + quota_weight x (the sites' total weight) x (the time
  // the visited sites' weight first reaches latency_quota of it). 0: the weighted latency alone.
  double latency_quota = 0.0;
  double quota_weight = 10.0;
  // m, 0 = off: an interior waypoint of a flown path whose clearance (the ESDF) is below this holds
  // the direction of travel instead of the early turn to the view's yaw, as DEP holds it through
  // doorways. Tried against the controller's fallbacks for the turned body's reach in env3's
  // process set; they were no fewer with it (docs/planner.md, "The latency tour weighed by the
  // gain, with object pockets"), so it is off.
  double square_clearance = 0.0;
  // The grid search (grid_search.hpp): coarse cells of search_step voxels for travel costs, and
  // how much more a step costs where the clearance is below collision.passage_clearance.
  int search_step = 2;
  double low_clearance_penalty = 1.0;
  // Settled coarse cells per cycle for the clusters' travel costs at most; the rest wait for the
  // next cycle (estimated meanwhile), so a burst of new clusters does not stall one cycle.
  int cost_budget = 120000;
};

// The known-map oracle (oracle_strategy.hpp; docs/planner.md, "The known-map oracle"). It knows
// the world (the evaluator's ground truth), so none of this is exploration: viewpoints on a
// lattice of the true free space, a greedy set cover of the target set T, a tour through them.
// The body, clearances, heights (sampling.z_min/z_max), camera and range (gain.*), yaw bins
// (gain.yaw_bins) and travel time (cost.*) are the other planners'.
struct OracleConfig {
  double spacing = 0.5;      // m, horizontal pitch of the lattice of candidate viewpoints
  double height_step = 0.5;  // m, its vertical pitch, from sampling.z_min up
  // Visibility rays per candidate: around it (360°) and across the camera's vertical field of
  // view. 384 x 64 are 0.94° x 1.15° apart, a voxel at 5-6 m; the real camera (0.14° a pixel)
  // sees at least what they see. What the rays miss between them far away the cover must find
  // elsewhere: with 256 x 48 it picked 34 viewpoints in env1, with 384 x 64 24.
  int rays_azimuth = 384;
  int rays_elevation = 64;
  // The tour must see this share of what all candidates together see of T (the observable part).
  double cover_fraction = 0.99;
  // m: legs keep this far from obstacles where there is room (the path search charges
  // clearance_penalty per metre flown and per metre below it), so they go through the middle of
  // doorways and rooms, as far as they can from walls the live map may not know yet.
  double preferred_clearance = 0.6;
  double clearance_penalty = 20.0;
  int exact_tour_max = 12;  // tours of at most this many viewpoints are solved exactly (DP)
  // The tour's first pass: from the start, the pick that shows the most new T voxels per
  // (second of travel)^e, again and again, until this share of the observable part and
  // target_share of T are shown; then one tour through the rest (0 and 0: a single tour through
  // every pick, the fastest to the last voxel). e is 0.25, 0.5, 0.75 or 1 (1: per second, the
  // many small views near the vehicle first; below 1 the larger views farther away, which the
  // camera also sees much on the way to), and the views are flown in the order walked or in that
  // of the shortest tour through them: whichever of the eight schedules shows target_share of T
  // soonest by the model (a view's voxels counted on arrival there). env3: 95 % of T at 137 s
  // with e = 0.5 walked alone, DEP 119 s (docs/planner.md, "The known-map oracle").
  double first_pass = 0.9;
  double target_share = 0.95;  // of T: the evaluator's Time_95
  // ... and the share of the evaluator's Time_r: the schedule is chosen (and reordered) for the
  // sum of the model's times to the two shares, so that it bounds both.
  double early_share = 0.85;
  // Objectives the first pass's reordering (Or-opt, 2-opt, drops judged by the model's time to
  // target_share of T) may ask for; 0: the schedule as chosen. env1-3 converge well within 3000;
  // the 600 m² world's 71-view schedule did not (Time_95 164 s flown, level with fuel; 160 s
  // with this bound, docs/planner.md "The known-map oracle").
  int improve_evaluations = 20000;
  // >= 0: four more schedules, the walk's views to early_share reordered for that time alone,
  // then walked on to target_share and reordered for it with the early time held within this
  // share of its best; the one flown is then the schedule whose worse time, each relative to the
  // soonest of any schedule, is lowest, and the log lists them all. Negative: the schedule of the
  // lowest sum. Measured, not the default: one flight cannot have both (env3: 85 % at 50 s
  // modelled costs 95 % at 106 s, against 62 / 81 s), docs/planner.md "The known-map oracle".
  double early_first_slack = -1.0;
  int max_attempts = 5;  // plans toward one viewpoint (braked, rejected, held short) before it is skipped
  // A viewpoint is flown to while at least this many of the T voxels only it (of those not yet
  // flown) shows are unknown in the live map; 1: while any is. The camera passing a viewpoint on
  // a chain in the process set leaves a voxel or two of its share unknown, and at 1 one such voxel
  // sent env3's vehicle back 5 m to it twice, 45 m flown between 45 and 115 s with coverage flat
  // at 68 % (docs/planner.md, "The known-map oracle"). A share of the view's voxels instead (a
  // tenth) skipped 63 of 99 views in env3's closed loop and left 1 point of T unseen.
  int needed_voxels = 10;
  // Viewpoints one path flies through at most: on past a viewpoint while the turn into it takes
  // no longer than the flight (the heading keeps up), so the vehicle does not stop at each; 1:
  // one goal per viewpoint, the vehicle stopping and dwelling at every one.
  int chain = 8;
  // MB kept of what the candidates see, packed (~3 bytes per voxel and candidate: 0.26 MB a
  // candidate in the 600 m² generated world, 1.9 GB for its 7072), and a quarter of it again for
  // the first pass's per-yaw lists: the set cover asks for a candidate's view again whenever one of
  // its bounds comes first, and beyond this a view is cast again each time (slower, the same
  // result; the oracle's summary line counts the casts). 2048 holds g224's views (600 m²).
  int cache_mb = 2048;
};

struct PlannerConfig {
  std::string planner =
      "semantic-dep";  // semantic-dep | dep | nbv | aep | fuel | oracle | semantic-room | semantic-fuel
  int64_t seed = 1;
  double rate_hz = 4.0;  // planning cycles per simulated second, at most
  CollisionConfig collision;
  SamplingConfig sampling;
  RoadmapConfig roadmap;
  GainConfig gain;
  CostConfig cost;
  RewardConfig reward;
  LoopConfig loop;
  ChargeConfig charge;
  NbvConfig nbv;
  AepConfig aep;
  FuelConfig fuel;
  OracleConfig oracle;
  RoomConfig room;
  SemanticFuelConfig semantic_fuel;

  PlannerKind kind() const { return parse_planner_kind(planner); }
};

// Strict loader (unknown keys and out-of-range values are errors naming the key).
void load(runtime::ConfigMap& m, PlannerConfig& c);

}  // namespace semx::planner
