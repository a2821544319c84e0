#include "semx/semantics/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace semx::semantics {

namespace {

constexpr int64_t kGridOffset = int64_t{1} << 20;
constexpr int64_t kGridMask = (int64_t{1} << 21) - 1;
constexpr std::size_t kMaxVoxelsPerTrack = 50000;

uint64_t pack3(int64_t a, int64_t b, int64_t c) {
  const auto f = [](int64_t x) {
    return static_cast<uint64_t>(std::clamp(x + kGridOffset, int64_t{0}, kGridMask));
  };
  return f(a) | (f(b) << 21) | (f(c) << 42);
}

// Gap between two boxes (0 when they touch or overlap).
double box_gap(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  const Eigen::Vector3d d = (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(Eigen::Vector3d::Zero());
  return d.norm();
}

double volume(const Eigen::AlignedBox3d& b) { return b.isEmpty() ? 0.0 : b.sizes().prod(); }

Eigen::AlignedBox3d inflate(const Eigen::AlignedBox3d& b, double r) {
  return Eigen::AlignedBox3d(b.min().array() - r, b.max().array() + r);
}

// One of the five faces whose cells are counted: +x, -x, +y, -y, +z (the bottom rests on
// something and is never counted).
struct Face {
  int axis;    // normal axis
  double dir;  // +1 or -1
  int a, b;    // in-plane axes
};
constexpr Face kFaces[5] = {{0, +1, 1, 2}, {0, -1, 1, 2}, {1, +1, 0, 2}, {1, -1, 0, 2}, {2, +1, 0, 1}};

// Cell indices along one in-plane axis of a box: world-aligned cells of size `cell` that
// intersect [lo, hi].
void cell_range(double lo, double hi, double cell, int64_t& i0, int64_t& i1) {
  i0 = static_cast<int64_t>(std::floor(lo / cell));
  i1 = static_cast<int64_t>(std::floor(hi / cell));
  if (i1 > i0 && hi - static_cast<double>(i1) * cell < 1e-9) --i1;  // hi on a cell border
}

// How much nearer than a surface point a measurement may be and still be that surface: depth
// noise (about 3 sigma of the Kinect-like model at these ranges) plus the few centimetres by which
// voxel means and the box's faces sit inside the true surface. Walls between rooms are 10 cm
// thick: anything looser lets an object be "seen" through the wall it stands against.
double surface_tolerance(double z) { return 0.04 + 0.015 * z; }

// Depth (m) measured at pixel (u, v); +inf for no return, NaN for no measurement.
double measured_depth(const Frame& f, int u, int v) {
  const uint16_t d = f.depth[static_cast<std::size_t>(v) * f.camera.width + u];
  if (d == runtime::kDepthNoReturn) return std::numeric_limits<double>::infinity();
  if (d == runtime::kDepthInvalid) return std::numeric_limits<double>::quiet_NaN();
  return d * 1e-3;
}

}  // namespace

double Track::probability() const { return 1.0 / (1.0 + std::exp(-log_odds)); }

ObjectTracker::ObjectTracker(const SemanticsConfig& config) : config_(config) {}

void ObjectTracker::clear() {
  tracks_.clear();
  frames_ = 0;
}

uint64_t ObjectTracker::voxel_key(const Eigen::Vector3f& p) const {
  const double inv = 1.0 / config_.lift.voxel_size;
  return pack3(static_cast<int64_t>(std::floor(p.x() * inv)), static_cast<int64_t>(std::floor(p.y() * inv)),
               static_cast<int64_t>(std::floor(p.z() * inv)));
}

double ObjectTracker::association_cost(const Track& t, const Detection3D& d) const {
  if (t.cls != d.cls || t.box.isEmpty() || d.box.isEmpty()) return -1.0;
  const double gap = box_gap(t.box, d.box);
  if (gap > config_.tracking.gate_distance) return -1.0;
  // Among tracks within the gate, prefer the one whose box centre is nearest.
  return gap + 0.25 * (t.box.center() - d.box.center()).norm();
}

bool ObjectTracker::in_view(const Track& t, const Frame& f) const {
  if (t.shape.empty() || t.box.isEmpty()) return false;
  const auto& cam = f.camera;
  const Eigen::Isometry3d world_to_cam = f.pose.inverse();
  // Cheap rejection first: the box's bounding sphere against the depth range.
  const Eigen::Vector3d c = world_to_cam * t.box.center();
  const double radius = 0.5 * t.box.sizes().norm();
  if (c.z() + radius < cam.min_range || c.z() - radius > cam.max_range) return false;

  // Each sampled voxel that is in the image, in range and not hidden covers a square of
  // fx * voxel / z pixels (grown when sampling skips voxels); the union of these squares on a
  // grid of 4x4-pixel tiles estimates the object's silhouette. A union, not a sum: the top of a
  // table seen at a grazing angle, or a door seen edge-on, covers a thin band, not its area.
  constexpr int kTile = 4;
  const int tiles_u = (cam.width + kTile - 1) / kTile, tiles_v = (cam.height + kTile - 1) / kTile;
  std::vector<uint8_t>& covered = tiles_;
  covered.assign(static_cast<std::size_t>(tiles_u) * tiles_v, 0);
  const std::size_t step = std::max<std::size_t>(1, t.shape.size() / 512);
  const double grow = std::sqrt(static_cast<double>(step));
  const double voxel = config_.lift.voxel_size;
  int visible = 0, tiles = 0;
  for (std::size_t i = 0; i < t.shape.size(); i += step) {
    const Eigen::Vector3d q = world_to_cam * t.shape[i].cast<double>();
    double u, v;
    // Near the end of the range depth noise decides whether the surface is measured (and
    // labelled) at all: such voxels are not counted.
    if (q.z() < cam.min_range || q.z() > cam.max_range - 0.25 || !cam.project(q, u, v)) continue;
    const int iu = static_cast<int>(std::lround(u)), iv = static_cast<int>(std::lround(v));
    if (iu < 0 || iv < 0 || iu >= cam.width || iv >= cam.height) continue;
    const double d = measured_depth(f, iu, iv);
    if (std::isnan(d) || d < q.z() - surface_tolerance(q.z())) continue;  // unknown, or hidden
    ++visible;
    const double half = 0.5 * grow * cam.fx * voxel / q.z();
    const int tu0 = std::max(0, static_cast<int>((u - half) / kTile));
    const int tu1 = std::min(tiles_u - 1, static_cast<int>((u + half) / kTile));
    const int tv0 = std::max(0, static_cast<int>((v - half) / kTile));
    const int tv1 = std::min(tiles_v - 1, static_cast<int>((v + half) / kTile));
    for (int tv = tv0; tv <= tv1; ++tv) {
      for (int tu = tu0; tu <= tu1; ++tu) {
        uint8_t& cell = covered[static_cast<std::size_t>(tv) * tiles_u + tu];
        if (!cell) cell = 1, ++tiles;
      }
    }
  }
  return visible >= 8 && tiles * kTile * kTile >= 4 * config_.detector.min_area_px;
}

void ObjectTracker::refit_box(Track& t) const {
  int best = 0;
  for (const auto& [key, v] : t.voxels) best = std::max(best, v.frames);
  const int need = std::max({1, std::min(config_.tracking.voxel_min_observations, t.observations),
                             static_cast<int>(std::ceil(config_.tracking.voxel_min_fraction * best))});
  Eigen::AlignedBox3d box;
  t.shape.clear();
  for (const auto& [key, v] : t.voxels) {
    if (v.frames < need) continue;
    t.shape.push_back(v.mean());
    box.extend(t.shape.back().cast<double>());
  }
  t.box = box;
}

void ObjectTracker::absorb(Track& t, const Detection3D& d, const Frame& f) {
  if (t.observations == 0) t.first_utime = f.utime;
  ++t.observations;
  ++t.frames_in_view;
  t.last_utime = f.utime;
  t.observation_span_utime = t.last_utime - t.first_utime;
  t.log_odds = std::min(config_.tracking.log_odds_max, t.log_odds + config_.tracking.log_odds_hit);
  t.score_sum += d.score;
  if (d.instance != 0) {
    const int n = ++t.instance_votes[d.instance];
    if (t.instance == 0 || (t.instance != d.instance && n > t.instance_votes[t.instance]))
      t.instance = d.instance;
  }
  for (const auto& p : d.points) {
    const uint64_t key = voxel_key(p);
    auto it = t.voxels.find(key);
    if (it == t.voxels.end()) {
      if (t.voxels.size() >= kMaxVoxelsPerTrack) continue;
      it = t.voxels.emplace(key, SurfaceVoxel{}).first;
    }
    SurfaceVoxel& v = it->second;
    v.sum += p;
    ++v.points;
    if (v.last_frame != frames_) {
      v.last_frame = frames_;
      ++v.frames;
    }
  }
  refit_box(t);
}

void ObjectTracker::update_cells(Track& t, const Frame& f) const {
  if (t.box.isEmpty()) return;
  const auto& cam = f.camera;
  const auto& tc = config_.tracking;
  const double cell = tc.face_cell;
  const Eigen::Isometry3d world_to_cam = f.pose.inverse();
  const Eigen::Vector3d eye = f.pose.translation();

  // Depth at the pixel of world point p, with p's own depth; false outside image or range.
  auto look = [&](const Eigen::Vector3d& p, double& z, double& measured) {
    const Eigen::Vector3d q = world_to_cam * p;
    double u, v;
    if (q.z() < cam.min_range || q.z() > cam.max_range || !cam.project(q, u, v)) return false;
    const int iu = static_cast<int>(std::lround(u)), iv = static_cast<int>(std::lround(v));
    if (iu < 0 || iv < 0 || iu >= cam.width || iv >= cam.height) return false;
    z = q.z();
    measured = measured_depth(f, iu, iv);
    return !std::isnan(measured);
  };

  for (int fi = 0; fi < 5; ++fi) {
    const Face& face = kFaces[fi];
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[face.axis] = face.dir;
    const double plane = face.dir > 0 ? t.box.max()[face.axis] : t.box.min()[face.axis];
    int64_t a0, a1, b0, b1;
    cell_range(t.box.min()[face.a], t.box.max()[face.a], cell, a0, a1);
    cell_range(t.box.min()[face.b], t.box.max()[face.b], cell, b0, b1);
    for (int64_t i = a0; i <= a1; ++i) {
      for (int64_t j = b0; j <= b1; ++j) {
        Eigen::Vector3d p;
        p[face.axis] = plane;
        p[face.a] =
            std::clamp((static_cast<double>(i) + 0.5) * cell, t.box.min()[face.a], t.box.max()[face.a]);
        p[face.b] =
            std::clamp((static_cast<double>(j) + 0.5) * cell, t.box.min()[face.b], t.box.max()[face.b]);
        const uint64_t key = static_cast<uint64_t>(fi) << 61 | pack3(i, j, 0);
        auto it = t.cells.find(key);
        const uint8_t state = it == t.cells.end() ? 0 : it->second;
        if (state == kSeen) continue;
        double z, d;
        uint8_t next = state;
        // Seen: the camera is on the face's outer side and the ray reaches the cell.
        const Eigen::Vector3d to_eye = eye - p;
        if (to_eye.dot(n) > 0.15 * to_eye.norm() && look(p, z, d) && d >= z - 0.02 - surface_tolerance(z)) {
          next = kSeen;
        }
        // Could be seen: the space just in front of the cell was seen free.
        if (next == 0 && look(p + tc.free_probe * n, z, d) && d > z + 0.05) next = kCandidate;
        if (next != state) t.cells[key] = next;
      }
    }
  }
}

void ObjectTracker::update_observed_fraction(Track& t) const {
  if (t.box.isEmpty()) return;
  const double cell = config_.tracking.face_cell;
  std::size_t total = 0, known = 0, seen = 0;
  int sides_seen = 0;
  for (int fi = 0; fi < 5; ++fi) {
    const Face& face = kFaces[fi];
    int64_t a0, a1, b0, b1;
    cell_range(t.box.min()[face.a], t.box.max()[face.a], cell, a0, a1);
    cell_range(t.box.min()[face.b], t.box.max()[face.b], cell, b0, b1);
    std::size_t face_total = 0, face_seen = 0;
    for (int64_t i = a0; i <= a1; ++i) {
      for (int64_t j = b0; j <= b1; ++j) {
        ++face_total;
        const auto it = t.cells.find(static_cast<uint64_t>(fi) << 61 | pack3(i, j, 0));
        if (it == t.cells.end()) continue;
        ++known;
        if (it->second == kSeen) ++face_seen;
      }
    }
    total += face_total;
    seen += face_seen;
    if (face.axis != 2 && 4 * face_seen >= face_total) ++sides_seen;
  }
  t.observed_fraction = known ? static_cast<double>(seen) / known : 0.0;
  t.known_fraction = total ? static_cast<double>(known) / total : 0.0;
  // Two sides seen: a box seen from one side only is flat, and its few cells would say "done".
  // The box and the cells change as more is seen, so the state is re-decided on every update,
  // with 0.1 of hysteresis on the fraction so that a region does not flicker at the threshold.
  const auto& tc = config_.tracking;
  const bool enough = t.known_fraction >= tc.min_known_fraction && sides_seen >= 2;
  if (enough && t.observed_fraction >= tc.fully_observed_fraction) {
    t.fully_observed = true;
  } else if (!enough || t.observed_fraction < tc.fully_observed_fraction - 0.1) {
    t.fully_observed = false;
  }
}

void ObjectTracker::mark_confusions() {
  const double ratio = config_.tracking.confusion_ratio;
  const double pad = 0.5 * config_.lift.voxel_size;
  for (Track& t : tracks_) {
    t.confused = false;
    if (!(ratio > 0) || t.box.isEmpty()) continue;
    const Eigen::AlignedBox3d bt = inflate(t.box, pad);
    for (const Track& o : tracks_) {
      if (o.cls == t.cls || o.box.isEmpty() || o.observations < ratio * t.observations) continue;
      const Eigen::AlignedBox3d bo = inflate(o.box, pad);
      if (volume(bt.intersection(bo)) >= config_.tracking.merge_overlap * std::min(volume(bt), volume(bo))) {
        t.confused = true;
        break;
      }
    }
  }
}

void ObjectTracker::merge_overlapping(TrackerStats& stats) {
  const double pad = 0.5 * config_.lift.voxel_size;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    for (std::size_t j = i + 1; j < tracks_.size(); ++j) {
      Track& a = tracks_[i];
      Track& b = tracks_[j];
      if (a.cls != b.cls || a.box.isEmpty() || b.box.isEmpty()) continue;
      const Eigen::AlignedBox3d ba = inflate(a.box, pad), bb = inflate(b.box, pad);
      const double overlap = volume(ba.intersection(bb)) / std::min(volume(ba), volume(bb));
      if (!(overlap >= config_.tracking.merge_overlap)) continue;
      // Keep the region (else the older track) and its id.
      const bool keep_a = a.region != b.region ? a.region : a.id < b.id;
      Track& keep = keep_a ? a : b;
      Track& gone = keep_a ? b : a;
      for (const auto& [key, v] : gone.voxels) {
        SurfaceVoxel& k = keep.voxels[key];
        k.sum += v.sum;
        k.points += v.points;
        k.frames = std::max(k.frames, v.frames);
        k.last_frame = std::max(k.last_frame, v.last_frame);
      }
      for (const auto& [key, s] : gone.cells) {
        uint8_t& k = keep.cells[key];
        k = std::max(k, s);
      }
      for (const auto& [id, n] : gone.instance_votes) keep.instance_votes[id] += n;
      int best = 0;
      for (const auto& [id, n] : keep.instance_votes) {
        if (n > best) best = n, keep.instance = id;
      }
      keep.observations += gone.observations;
      keep.frames_in_view = std::max(keep.frames_in_view, gone.frames_in_view);
      keep.score_sum += gone.score_sum;
      keep.first_utime = std::min(keep.first_utime, gone.first_utime);
      keep.last_utime = std::max(keep.last_utime, gone.last_utime);
      keep.observation_span_utime = keep.last_utime - keep.first_utime;
      keep.log_odds = std::max(keep.log_odds, gone.log_odds);
      keep.fully_observed = keep.fully_observed || gone.fully_observed;
      refit_box(keep);
      update_observed_fraction(keep);
      if (!keep_a) std::swap(a, b);  // the kept track stays at index i
      tracks_.erase(tracks_.begin() + static_cast<std::ptrdiff_t>(j));
      ++stats.merged;
      j = i;  // the kept track changed: compare it with every later track again
    }
  }
}

TrackerStats ObjectTracker::update(const Frame& frame, const std::vector<Detection3D>& detections) {
  TrackerStats stats;
  ++frames_;
  const auto& tc = config_.tracking;

  // Association: cheapest pairs first, one-to-one.
  struct Pair {
    double cost;
    std::size_t det, track;
  };
  std::vector<Pair> pairs;
  for (std::size_t d = 0; d < detections.size(); ++d) {
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
      const double c = association_cost(tracks_[t], detections[d]);
      if (c >= 0) pairs.push_back({c, d, t});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.cost != b.cost ? a.cost < b.cost : (a.det != b.det ? a.det < b.det : a.track < b.track);
  });
  std::vector<char> det_used(detections.size(), 0), track_used(tracks_.size(), 0);
  for (const Pair& p : pairs) {
    if (det_used[p.det] || track_used[p.track]) continue;
    det_used[p.det] = track_used[p.track] = 1;
    absorb(tracks_[p.track], detections[p.det], frame);
    ++stats.matched;
  }
  // Tracks that should have been detected and were not.
  const std::size_t existing = tracks_.size();
  for (std::size_t t = 0; t < existing; ++t) {
    if (track_used[t] || !in_view(tracks_[t], frame)) continue;
    track_used[t] = 2;
    ++tracks_[t].frames_in_view;
    tracks_[t].log_odds -= tracks_[t].region ? tc.region_log_odds_miss : tc.log_odds_miss;
    ++stats.missed;
  }
  for (std::size_t d = 0; d < detections.size(); ++d) {
    if (det_used[d] || detections[d].points.empty()) continue;
    Track t;
    t.id = next_id_++;
    t.cls = detections[d].cls;
    absorb(t, detections[d], frame);
    tracks_.push_back(std::move(t));
    track_used.push_back(1);
    ++stats.created;
  }
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    if (!track_used[t]) continue;
    update_cells(tracks_[t], frame);
    update_observed_fraction(tracks_[t]);
  }
  merge_overlapping(stats);
  mark_confusions();

  const int64_t timeout = static_cast<int64_t>(tc.tentative_timeout_s * 1e6);
  const auto before = tracks_.size();
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const Track& t) {
                                 return t.log_odds < tc.drop_log_odds ||
                                        (!t.region && frame.utime - t.last_utime > timeout);
                               }),
                tracks_.end());
  stats.deleted = static_cast<int>(before - tracks_.size());

  const int64_t span = static_cast<int64_t>(std::llround(tc.min_duration_s * 1e6));
  for (Track& t : tracks_) {
    if (t.confused) {
      t.region = false;  // a label confusion that slipped through: withdrawn
      continue;
    }
    if (t.region || t.observations < tc.min_observations || t.observation_span_utime < span ||
        t.probability() < tc.promote_probability) {
      continue;
    }
    t.region = true;
    t.region_utime = frame.utime;
    ++stats.promoted;
  }
  return stats;
}

}  // namespace semx::semantics
