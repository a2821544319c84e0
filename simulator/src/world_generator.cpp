#include "semx/simulator/world_generator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "semx/core/random.hpp"

namespace semx::simulator {
namespace {

using C = SemanticClass;
constexpr double kMinRoomSide = 2.5;
constexpr double kDoorHeight = 2.1;

struct Rect {
  double x0, y0, x1, y1;
  double w() const { return x1 - x0; }
  double h() const { return y1 - y0; }
  bool overlaps(const Rect& o, double gap = 0.0) const {
    return x0 < o.x1 + gap && o.x0 < x1 + gap && y0 < o.y1 + gap && o.y0 < y1 + gap;
  }
};

// A straight interior wall on the line {axis coordinate = c}, spanning [s0, s1] along the other
// axis (axis 0: x = c, the wall runs along y).
struct Cut {
  int axis;
  double c, s0, s1;
};

// Footprints of furniture: width along the wall, depth into the room, height.
struct Item {
  C cls;
  double w, d, h;
  bool cylinder = false;
};

class Builder {
 public:
  Builder(const GeneratorOptions& o, uint64_t attempt) : o_(o), rng_(core::mix_seed(o.seed, attempt)) {}

  bool build(GeneratedWorld& out) {
    const double aspect = rng_.uniform(1.0, 1.6);
    // Dimensions on a 5 cm grid so every derived coordinate rounds exactly to the millimetre.
    W_ = std::round(std::sqrt(o_.area * aspect) * 20.0) / 20.0;
    D_ = std::round(o_.area / W_ * 20.0) / 20.0;
    rooms_.clear();
    cuts_.clear();
    if (!split({0, 0, W_, D_}, rooms_wanted())) return false;
    World& w = out.world;
    w = World();
    w.name = "generated-s" + std::to_string(o_.seed) + "-a" +
             std::to_string(static_cast<int>(std::lround(o_.area))) + "-r" + std::to_string(rooms_wanted());
    const double t = o_.wall_thickness, H = o_.ceiling_height;
    w.bounds = {{-t, -t, -0.1}, {W_ + t, D_ + t, H + 0.1}};
    add(w, Solid::box(C::kFloor, {W_ / 2, D_ / 2, -0.05}, {W_ + 2 * t, D_ + 2 * t, 0.1}));
    add(w, Solid::box(C::kCeiling, {W_ / 2, D_ / 2, H + 0.05}, {W_ + 2 * t, D_ + 2 * t, 0.1}));
    add(w, Solid::box(C::kWall, {W_ / 2, -t / 2, H / 2}, {W_ + 2 * t, t, H}));
    add(w, Solid::box(C::kWall, {W_ / 2, D_ + t / 2, H / 2}, {W_ + 2 * t, t, H}));
    add(w, Solid::box(C::kWall, {-t / 2, D_ / 2, H / 2}, {t, D_, H}));
    add(w, Solid::box(C::kWall, {W_ + t / 2, D_ / 2, H / 2}, {t, D_, H}));
    for (const auto& cut : cuts_) {
      if (!add_cut_wall(w, cut)) return false;
    }
    add_door_leaves(w);
    out.rooms.clear();
    for (size_t r = 0; r < rooms_.size(); ++r) {
      Rect room = interior(rooms_[r]);
      add_windows(w, room);
      furnish(w, room, static_cast<int>(r));
      out.rooms.push_back({{room.x0, room.y0, 0.0}, {room.x1, room.y1, H}});
    }
    const Rect first = interior(rooms_[0]);
    w.start.position = {0.5 * (first.x0 + first.x1), 0.5 * (first.y0 + first.y1), o_.flight_height};
    w.start.yaw = 0;
    if (first_solid_hit_by_body(w, w.start.position, 0) >= 0) return false;
    validate_world(w);
    return true;
  }

  int rooms_wanted() const {
    return o_.rooms > 0 ? o_.rooms : std::max(1, static_cast<int>(std::lround(o_.area / 25.0)));
  }

 private:
  void add(World& w, Solid s) {
    // Positions rounded to the millimetre keep generated files short and readable.
    for (int a = 0; a < 3; ++a) {
      s.center[a] = std::round(s.center[a] * 1000.0) / 1000.0;
      s.size[a] = std::round(s.size[a] * 1000.0) / 1000.0;
    }
    w.solids.push_back(s);
  }

  // Guillotine partition into n rooms, cutting across the longer side in proportion to the
  // rooms each part receives.
  bool split(const Rect& r, int n) {
    if (n == 1) {
      rooms_.push_back(r);
      return true;
    }
    const int n1 = n / 2 + (n % 2 == 1 && rng_.bernoulli(0.5) ? 1 : 0);
    const int axis = r.w() >= r.h() ? 0 : 1;
    const double len = axis == 0 ? r.w() : r.h();
    double frac = static_cast<double>(n1) / n + rng_.uniform(-0.08, 0.08);
    double c = (axis == 0 ? r.x0 : r.y0) + frac * len;
    c = std::round(c * 20.0) / 20.0;  // on a 5 cm grid
    Rect a = r, b = r;
    if (axis == 0) {
      a.x1 = c;
      b.x0 = c;
    } else {
      a.y1 = c;
      b.y0 = c;
    }
    const double need = kMinRoomSide + o_.wall_thickness;
    if (std::min(a.w(), a.h()) < need || std::min(b.w(), b.h()) < need) return false;
    cuts_.push_back({axis, c, axis == 0 ? r.y0 : r.x0, axis == 0 ? r.y1 : r.x1});
    return split(a, n1) && split(b, n - n1);
  }

  Rect interior(const Rect& r) const {
    const double h = 0.5 * o_.wall_thickness;
    auto inner = [&](double v, double outer_edge, double sign) {
      return std::abs(v - outer_edge) < 1e-9 ? v : v + sign * h;
    };
    return {inner(r.x0, 0, 1), inner(r.y0, 0, 1), inner(r.x1, W_, -1), inner(r.y1, D_, -1)};
  }

  bool add_cut_wall(World& w, const Cut& cut) {
    const double t = o_.wall_thickness, H = o_.ceiling_height;
    // Junctions: where a perpendicular wall meets this one; a doorway must keep clear of them.
    std::vector<double> stops{cut.s0, cut.s1};
    for (const auto& o : cuts_) {
      if (o.axis == cut.axis) continue;
      if (o.c > cut.s0 && o.c < cut.s1 && (std::abs(o.s0 - cut.c) < 1e-9 || std::abs(o.s1 - cut.c) < 1e-9)) {
        stops.push_back(o.c);
      }
    }
    std::sort(stops.begin(), stops.end());
    const double door = std::round(rng_.uniform(0.9, 1.1) * 20.0) / 20.0;
    const double margin = 0.25 + t;
    std::vector<std::pair<double, double>> options;
    for (size_t i = 0; i + 1 < stops.size(); ++i) {
      if (stops[i + 1] - stops[i] >= door + 2 * margin)
        options.push_back({stops[i] + margin, stops[i + 1] - margin - door});
    }
    if (options.empty()) return false;
    const auto& [lo, hi] = options[rng_.uniform_int(0, static_cast<int>(options.size()) - 1)];
    const double d0 = std::round(rng_.uniform(lo, hi) * 20.0) / 20.0, d1 = d0 + door;
    auto wall = [&](double a, double b, double z0, double z1, C cls, double thick) {
      if (b - a < 1e-3) return;
      const double mid = 0.5 * (a + b);
      const Eigen::Vector3d center = cut.axis == 0 ? Eigen::Vector3d(cut.c, mid, 0.5 * (z0 + z1))
                                                   : Eigen::Vector3d(mid, cut.c, 0.5 * (z0 + z1));
      const Eigen::Vector3d size =
          cut.axis == 0 ? Eigen::Vector3d(thick, b - a, z1 - z0) : Eigen::Vector3d(b - a, thick, z1 - z0);
      add(w, Solid::box(cls, center, size));
    };
    wall(cut.s0, d0, 0, H, C::kWall, t);
    wall(d1, cut.s1, 0, H, C::kWall, t);
    wall(d0, d1, kDoorHeight, H, C::kWall, t);  // lintel
    doors_.push_back({cut, d0, d1});
    // Nothing may stand in front of a doorway on either side (the leaf's side included).
    const double reach = 0.5 * t + 1.3;
    keep_out_.push_back(cut.axis == 0 ? Rect{cut.c - reach, d0 - 0.6, cut.c + reach, d1 + 0.6}
                                      : Rect{d0 - 0.6, cut.c - reach, d1 + 0.6, cut.c + reach});
    return true;
  }

  // An open leaf stands at right angles to its wall beside the gap. Of the four ways to hang
  // it (either jamb, either room), take one that keeps clear of the space in front of every
  // other doorway; a leaf that would obstruct one in every way is left out.
  void add_door_leaves(World& w) {
    const double t = o_.wall_thickness;
    auto front = [&](const Door& d) {  // the approach zone of a doorway, both sides
      const double reach = 0.5 * t + 0.9;
      return d.cut.axis == 0 ? Rect{d.cut.c - reach, d.d0 - 0.1, d.cut.c + reach, d.d1 + 0.1}
                             : Rect{d.d0 - 0.1, d.cut.c - reach, d.d1 + 0.1, d.cut.c + reach};
    };
    for (size_t i = 0; i < doors_.size(); ++i) {
      const Door& d = doors_[i];
      const double width = d.d1 - d.d0;
      const int first = rng_.uniform_int(0, 3);
      for (int k = 0; k < 4; ++k) {
        const int option = (first + k) % 4;
        const double along = option < 2 ? d.d0 - 0.03 : d.d1 + 0.03;
        const double side = option % 2 == 0 ? 1.0 : -1.0;
        const double across = d.cut.c + side * (0.5 * t + 0.5 * width + 0.02);
        const Rect fp = d.cut.axis == 0
                            ? Rect{across - 0.5 * width, along - 0.02, across + 0.5 * width, along + 0.02}
                            : Rect{along - 0.02, across - 0.5 * width, along + 0.02, across + 0.5 * width};
        bool clear = true;
        for (size_t j = 0; j < doors_.size(); ++j) {
          if (j != i && fp.overlaps(front(doors_[j]))) clear = false;
        }
        if (!clear) continue;
        const Eigen::Vector3d c(0.5 * (fp.x0 + fp.x1), 0.5 * (fp.y0 + fp.y1), 1.0);
        add(w, Solid::box(C::kDoor, c, {fp.w(), fp.h(), 2.0}));
        break;
      }
    }
  }

  void add_windows(World& w, const Rect& room) {
    const double t = o_.wall_thickness;
    // One window on a wall of the room that is an outer wall.
    struct Side {
      bool outer;
      int axis;  // axis of the wall normal
      double c, s0, s1;
    };
    const Side sides[4] = {{room.y0 <= 1e-9, 1, -t / 2, room.x0, room.x1},
                           {room.y1 >= D_ - 1e-9, 1, D_ + t / 2, room.x0, room.x1},
                           {room.x0 <= 1e-9, 0, -t / 2, room.y0, room.y1},
                           {room.x1 >= W_ - 1e-9, 0, W_ + t / 2, room.y0, room.y1}};
    std::vector<Side> outer;
    for (const auto& s : sides) {
      if (s.outer) outer.push_back(s);
    }
    if (outer.empty()) return;
    const Side& s = outer[rng_.uniform_int(0, static_cast<int>(outer.size()) - 1)];
    const double width = std::min(1.4, s.s1 - s.s0 - 1.0);
    if (width < 0.6) return;
    const double mid = 0.5 * (s.s0 + s.s1);
    // Slightly thicker than the wall (but inside the bounds) so it shows from the room.
    const double thick = t + 0.02;
    const double c = s.c + (s.c < 0.5 * (s.axis == 0 ? W_ : D_) ? 0.01 : -0.01);
    const Eigen::Vector3d center = s.axis == 0 ? Eigen::Vector3d(c, mid, 1.5) : Eigen::Vector3d(mid, c, 1.5);
    const Eigen::Vector3d size =
        s.axis == 0 ? Eigen::Vector3d(thick, width, 1.2) : Eigen::Vector3d(width, thick, 1.2);
    add(w, Solid::box(C::kWindow, center, size));
  }

  // Places an item against a random wall of the room; false if no free spot was found.
  bool place_against_wall(World& w, const Rect& room, const Item& item, std::vector<Rect>& placed,
                          double z0 = 0.0) {
    for (int attempt = 0; attempt < 40; ++attempt) {
      const int side = rng_.uniform_int(0, 3);
      const bool horizontal = side < 2;  // wall along x
      const double along_lo = (horizontal ? room.x0 : room.y0) + 0.5 * item.w + 0.05;
      const double along_hi = (horizontal ? room.x1 : room.y1) - 0.5 * item.w - 0.05;
      if (along_hi < along_lo) continue;
      const double along = rng_.uniform(along_lo, along_hi);
      const double off = 0.5 * item.d + 0.03;
      double cx, cy, sx, sy;
      if (horizontal) {
        cx = along;
        cy = side == 0 ? room.y0 + off : room.y1 - off;
        sx = item.w;
        sy = item.d;
      } else {
        cy = along;
        cx = side == 2 ? room.x0 + off : room.x1 - off;
        sx = item.d;
        sy = item.w;
      }
      if (place(w, item, {cx - sx / 2, cy - sy / 2, cx + sx / 2, cy + sy / 2}, placed, z0)) return true;
    }
    return false;
  }

  bool place(World& w, const Item& item, const Rect& fp, std::vector<Rect>& placed, double z0) {
    for (const auto& k : keep_out_) {
      if (fp.overlaps(k)) return false;
    }
    for (const auto& p : placed) {
      if (fp.overlaps(p, 0.1)) return false;
    }
    // The start pose's neighbourhood stays clear so the vehicle can always take off.
    if (!rooms_.empty()) {
      const Rect first = interior(rooms_[0]);
      const double sx = 0.5 * (first.x0 + first.x1), sy = 0.5 * (first.y0 + first.y1);
      if (fp.overlaps({sx - 0.6, sy - 0.6, sx + 0.6, sy + 0.6})) return false;
    }
    placed.push_back(fp);
    const Eigen::Vector3d c(0.5 * (fp.x0 + fp.x1), 0.5 * (fp.y0 + fp.y1), z0 + 0.5 * item.h);
    if (item.cylinder) {
      add(w, Solid::cylinder(item.cls, c, 0.5 * std::min(fp.w(), fp.h()), item.h));
    } else {
      add(w, Solid::box(item.cls, c, {fp.w(), fp.h(), item.h}));
    }
    return true;
  }

  void furnish(World& w, const Rect& room, int index) {
    std::vector<Rect> placed;
    const double area = room.w() * room.h();
    // Room kinds cycle so every apartment has a mix; small rooms become bathrooms.
    int kind = index % 4;
    if (area < 8.0 && index > 0) kind = 4;
    auto wall_item = [&](C cls, double wi, double d, double h, bool cyl = false) {
      return place_against_wall(w, room, {cls, wi, d, h, cyl}, placed);
    };
    auto plant = [&]() {
      const double r = rng_.uniform(0.15, 0.3);
      wall_item(C::kPlant, 2 * r, 2 * r, rng_.uniform(0.6, 1.4), true);
    };
    switch (kind) {
      case 0: {  // living room
        wall_item(C::kSofa, 2.0, 0.9, 0.85);
        if (wall_item(C::kCabinet, 1.4, 0.45, 0.5)) {
          const Rect& c = placed.back();
          const Eigen::Vector3d top(0.5 * (c.x0 + c.x1), 0.5 * (c.y0 + c.y1), 0.5 + 0.35);
          const bool along_x = c.w() > c.h();
          add(w, Solid::box(C::kTv, top,
                            along_x ? Eigen::Vector3d(1.1, 0.08, 0.7) : Eigen::Vector3d(0.08, 1.1, 0.7)));
        }
        wall_item(C::kShelf, 1.0, 0.35, 1.9);
        wall_item(C::kLamp, 0.3, 0.3, 1.6, true);
        plant();
        center_table(w, room, placed, 2);
        break;
      }
      case 1: {  // bedroom
        wall_item(C::kBed, 1.6, 2.0, 0.55);
        wall_item(C::kCabinet, 1.0, 0.6, 2.0);
        wall_item(C::kDesk, 1.2, 0.6, 0.75);
        wall_item(C::kChair, 0.45, 0.45, 0.9);
        wall_item(C::kLamp, 0.3, 0.3, 1.5, true);
        plant();
        break;
      }
      case 2: {  // kitchen
        wall_item(C::kRefrigerator, 0.7, 0.7, 1.8);
        wall_item(C::kCabinet, 1.6, 0.6, 0.9);
        wall_item(C::kSink, 0.8, 0.6, 0.9);
        wall_item(C::kShelf, 0.8, 0.35, 1.8);
        center_table(w, room, placed, 4);
        plant();
        break;
      }
      case 3: {  // study
        wall_item(C::kDesk, 1.4, 0.7, 0.75);
        wall_item(C::kChair, 0.45, 0.45, 0.9);
        wall_item(C::kShelf, 1.2, 0.35, 2.0);
        wall_item(C::kShelf, 0.9, 0.35, 1.8);
        wall_item(C::kSofa, 1.6, 0.85, 0.8);
        place_against_wall(w, room, {C::kTv, 1.0, 0.1, 0.6}, placed, 1.0);  // wall-mounted
        plant();
        break;
      }
      default: {  // bathroom
        wall_item(C::kToilet, 0.4, 0.65, 0.75);
        wall_item(C::kSink, 0.6, 0.5, 0.9);
        wall_item(C::kBathtub, 1.7, 0.75, 0.55);
        wall_item(C::kCabinet, 0.6, 0.35, 0.8);
        break;
      }
    }
  }

  // A table in the middle of the room with chairs around it (all below flight height).
  void center_table(World& w, const Rect& room, std::vector<Rect>& placed, int chairs) {
    const double tw = std::min(1.4, room.w() - 1.8), td = std::min(0.8, room.h() - 1.8);
    if (tw < 0.6 || td < 0.5) return;
    const double cx = 0.5 * (room.x0 + room.x1) + rng_.uniform(-0.3, 0.3);
    const double cy = 0.5 * (room.y0 + room.y1) + rng_.uniform(-0.3, 0.3);
    if (!place(w, {C::kTable, tw, td, 0.75}, {cx - tw / 2, cy - td / 2, cx + tw / 2, cy + td / 2}, placed,
               0.0)) {
      return;
    }
    const double offsets[4][2] = {{0, -1}, {0, 1}, {-1, 0}, {1, 0}};
    for (int k = 0; k < chairs; ++k) {
      const double px = cx + offsets[k][0] * (0.5 * tw + 0.35), py = cy + offsets[k][1] * (0.5 * td + 0.35);
      Solid chair = Solid::box(C::kChair, {px, py, 0.45}, {0.45, 0.45, 0.9}, rng_.uniform(-0.4, 0.4));
      const Aabb b = chair.bounds();
      const Rect fp{b.min.x(), b.min.y(), b.max.x(), b.max.y()};
      bool free = fp.x0 > room.x0 && fp.x1 < room.x1 && fp.y0 > room.y0 && fp.y1 < room.y1;
      for (const auto& k2 : keep_out_) free = free && !fp.overlaps(k2);
      for (size_t p = 0; p + 1 < placed.size(); ++p) free = free && !fp.overlaps(placed[p], 0.05);
      if (!free) continue;
      placed.push_back(fp);
      add(w, chair);
    }
  }

  GeneratorOptions o_;
  core::XoshiroRng rng_;
  double W_ = 0, D_ = 0;
  std::vector<Rect> rooms_;
  std::vector<Cut> cuts_;
  struct Door {
    Cut cut;
    double d0, d1;  // the gap along the wall
  };
  std::vector<Door> doors_;
  std::vector<Rect> keep_out_;
};

}  // namespace

GeneratedWorld generate_world(const GeneratorOptions& options) {
  if (!(options.area >= 9.0) || !(options.area <= 5000.0)) {
    throw std::invalid_argument("generator: area must be within [9, 5000] m²");
  }
  if (options.rooms < 0 || options.rooms > 64)
    throw std::invalid_argument("generator: rooms must be within [0, 64]");
  if (!(options.ceiling_height >= 2.0 && options.ceiling_height <= 6.0)) {
    throw std::invalid_argument("generator: ceiling height must be within [2, 6] m");
  }
  if (!(options.flight_height > 0.3 && options.flight_height < options.ceiling_height - 0.3)) {
    throw std::invalid_argument("generator: flight height must leave 0.3 m to floor and ceiling");
  }
  GeneratedWorld out;
  for (uint64_t attempt = 0; attempt < 200; ++attempt) {
    Builder b(options, attempt);
    if (b.build(out)) return out;
  }
  const int rooms =
      options.rooms > 0 ? options.rooms : std::max(1, static_cast<int>(std::lround(options.area / 25.0)));
  char msg[160];
  std::snprintf(msg, sizeof msg,
                "generator: cannot fit %d rooms of at least %.1f m a side with doorways into %.1f m²", rooms,
                kMinRoomSide, options.area);
  throw std::invalid_argument(msg);
}

}  // namespace semx::simulator
