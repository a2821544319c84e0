// Stage 3: tracking and fusion. Each 3D detection is associated with a track of the same class
// whose box lies within gate_distance (one-to-one per frame, cheapest first); unmatched
// detections start tentative tracks. A track fuses the surface voxels of its detections (the
// box, hence the centroid, comes from the voxels seen in at least voxel_min_observations
// frames), keeps an existence log-odds (up per detection, down per frame in which it should
// have been detected and was not), and becomes a region after K detections spanning T seconds
// of message time with enough existence probability. It also records which cells of its box's
// top and side faces have been seen (the observed fraction). docs/semantics.md has the rules.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "semx/semantics/config.hpp"
#include "semx/semantics/frame.hpp"
#include "semx/semantics/lifter.hpp"

namespace semx::semantics {

struct SurfaceVoxel {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();  // of the points that fell in it
  int points = 0;
  int frames = 0;  // frames that saw it
  int64_t last_frame = -1;
  Eigen::Vector3f mean() const { return sum / static_cast<float>(points); }
};

// Face cells of a track's box: kCandidate when the space in front of the cell has been seen
// free (the cell could be seen), kSeen when the camera saw the cell itself from outside.
enum CellState : uint8_t { kCandidate = 1, kSeen = 2 };

struct Track {
  int64_t id = 0;
  runtime::SemanticClass cls = runtime::SemanticClass::kNone;
  uint16_t instance = 0;    // the instance id seen most often (0 when unknown)
  Eigen::AlignedBox3d box;  // fused axis-aligned bounds, world
  int observations = 0;     // frames with an associated detection
  int frames_in_view = 0;   // frames in which it was in view (detected or not)
  int64_t first_utime = 0, last_utime = 0;
  int64_t observation_span_utime = 0;  // last_utime - first_utime when last observed
  double log_odds = 0.0;               // existence
  double score_sum = 0.0;              // of the detections' scores
  bool region = false;                 // promoted: published as a semantic region
  int64_t region_utime = -1;
  double observed_fraction = 0.0;  // seen / (seen ∪ candidate) face cells
  double known_fraction = 0.0;     // (seen ∪ candidate) / all top and side face cells
  bool fully_observed = false;     // docs/semantics.md, "the fully-observed rule"
  bool confused = false;           // dominated by an overlapping track of another class

  std::unordered_map<uint64_t, SurfaceVoxel> voxels;
  std::unordered_map<uint64_t, uint8_t> cells;
  std::map<uint16_t, int> instance_votes;
  std::vector<Eigen::Vector3f> shape;  // means of the voxels that shape the box (for in_view)

  Eigen::Vector3d centroid() const { return box.center(); }
  Eigen::Vector3d extent() const { return box.sizes(); }
  double probability() const;
  double mean_score() const { return observations ? score_sum / observations : 0.0; }
};

struct TrackerStats {
  int matched = 0;
  int created = 0;
  int merged = 0;
  int deleted = 0;
  int promoted = 0;
  int missed = 0;  // tracks in view without a detection
};

class ObjectTracker {
 public:
  explicit ObjectTracker(const SemanticsConfig& config);

  // One frame's detections (all from `frame`, whose images decide what was in view).
  TrackerStats update(const Frame& frame, const std::vector<Detection3D>& detections);
  const std::vector<Track>& tracks() const { return tracks_; }
  void clear();

  // Whether `track` should have been detected in `frame`: the surface voxels that shape its box
  // (a sample of at most 512), projected into the image within the depth range (but not within
  // 0.25 m of its end) and not hidden behind a nearer measurement, cover 4x4-pixel tiles worth
  // at least 4 times the detector's minimum area (tiles overestimate a silhouette by up to a
  // tile around its edge).
  bool in_view(const Track& track, const Frame& frame) const;
  // The association cost of a detection with a track, or a negative number outside the gate.
  double association_cost(const Track& track, const Detection3D& det) const;

 private:
  void absorb(Track& t, const Detection3D& d, const Frame& frame);
  void refit_box(Track& t) const;
  void update_cells(Track& t, const Frame& frame) const;
  void update_observed_fraction(Track& t) const;
  void merge_overlapping(TrackerStats& stats);
  void mark_confusions();
  uint64_t voxel_key(const Eigen::Vector3f& p) const;

  SemanticsConfig config_;
  std::vector<Track> tracks_;
  int64_t next_id_ = 1;
  int64_t frames_ = 0;                  // update() calls: stamps which frame last saw a surface voxel
  mutable std::vector<uint8_t> tiles_;  // in_view()'s scratch image of covered tiles
};

}  // namespace semx::semantics
