// Builders shared by the semantics tests: synthetic frames painted by hand, and small worlds
// rendered by the simulator's rasteriser (known geometry at known poses).
#pragma once

#include <memory>
#include <vector>

#include "semantics_sim.hpp"
#include "semx/semantics/frame.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "semx/simulator/world.hpp"

namespace semx::semantics::test {

using runtime::SemanticClass;
using simulator::Solid;
using simulator::World;

// A frame from a camera at the world origin with the optical axis along world +x (level):
// every pixel sees nothing (depth no-return, no labels).
inline Frame blank_frame(int width = 640, int height = 480, int64_t utime = 0) {
  Frame f;
  f.utime = utime;
  f.camera.width = width;
  f.camera.height = height;
  f.camera.cx = width / 2.0;
  f.camera.cy = height / 2.0;
  f.pose.linear() = runtime::optical_in_body();
  f.depth.assign(f.pixels(), runtime::kDepthNoReturn);
  f.class_label.assign(f.pixels(), 0);
  f.instance_label.assign(f.pixels(), 0);
  return f;
}

// Paints a rectangle of one class/instance at one depth.
inline void paint(Frame& f, int x, int y, int w, int h, SemanticClass cls, uint16_t instance,
                  uint16_t depth_mm) {
  for (int v = y; v < y + h; ++v) {
    for (int u = x; u < x + w; ++u) {
      if (u < 0 || v < 0 || u >= f.camera.width || v >= f.camera.height) continue;
      const std::size_t i = static_cast<std::size_t>(v) * f.camera.width + u;
      f.class_label[i] = static_cast<uint16_t>(cls);
      f.instance_label[i] = instance;
      f.depth[i] = depth_mm;
    }
  }
}

// A closed room, interior [0, sx] x [0, sy] x [0, sz], plus `objects` (instances assigned).
inline World room(std::vector<Solid> objects, double sx = 6, double sy = 5, double sz = 2.7) {
  World w;
  const double t = 0.2;
  w.name = "room";
  w.bounds = {{-t, -t, -t}, {sx + t, sy + t, sz + t}};
  w.start.position = {0.6, 0.6, 1.4};
  using C = SemanticClass;
  w.solids.push_back(Solid::box(C::kFloor, {sx / 2, sy / 2, -t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(Solid::box(C::kCeiling, {sx / 2, sy / 2, sz + t / 2}, {sx + 2 * t, sy + 2 * t, t}));
  w.solids.push_back(Solid::box(C::kWall, {-t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx + t / 2, sy / 2, sz / 2}, {t, sy, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx / 2, -t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  w.solids.push_back(Solid::box(C::kWall, {sx / 2, sy + t / 2, sz / 2}, {sx + 2 * t, t, sz}));
  for (auto& o : objects) w.solids.push_back(o);
  simulator::validate_world(w);
  return w;
}

// Renders frames of a world from vehicle poses (body centre, yaw), like the simulator's camera.
class Scene {
 public:
  explicit Scene(World world) : world_(std::make_unique<World>(std::move(world))), raster_(*world_) {}
  const World& world() const { return *world_; }

  simulator::CameraFrame render_raw(const Eigen::Vector3d& body, double yaw, int64_t utime,
                                    int64_t frame_id) {
    simulator::VehicleState s;
    s.position = body;
    s.yaw = yaw;
    simulator::CameraFrame f;
    raster_.render(runtime::PinholeCamera{}, s.camera_pose(),
                   simulator::kRenderDepth | simulator::kRenderLabels, f);
    f.utime = utime;
    f.frame_id = frame_id;
    return f;
  }
  Frame render(const Eigen::Vector3d& body, double yaw, int64_t utime = 0, int64_t frame_id = 0) {
    return to_frame(render_raw(body, yaw, utime, frame_id));
  }

 private:
  std::unique_ptr<World> world_;
  simulator::Rasterizer raster_;
};

// Yaw that makes a vehicle at `from` look at `to`.
inline double look_at(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return std::atan2(to.y() - from.y(), to.x() - from.x());
}

}  // namespace semx::semantics::test
