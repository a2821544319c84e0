// Z-buffer triangle rasteriser of a world for the pinhole camera: the simulator's fast
// renderer. Per frame: bounding-sphere frustum culling of solids, back-face culling, clipping of
// triangles against the near plane (not dropping them), scan conversion sampling each pixel at
// its centre ray camera.ray(u, v). The depth buffer holds 1/z, which is affine in (u, v), with
// coefficients taken from the triangle's exact plane, so depth matches analytic ray casting to
// float precision.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "semx/runtime/pinhole_camera.hpp"
#include "semx/simulator/camera_frame.hpp"
#include "semx/simulator/mesh.hpp"

namespace semx::simulator {

struct RasterizerOptions {
  MeshOptions mesh;
  // Geometry closer than this is clipped away. Below min_range depth is reported invalid
  // anyway; the clip only has to be in front of the optical centre.
  double clip_near = 0.01;
  // RGB shows surfaces up to this distance (m, along z) when larger than the camera's
  // max_range, so images for people are not cut at the depth range. Depth and labels always
  // stop at max_range.
  double rgb_far = 0.0;
};

class Rasterizer {
 public:
  explicit Rasterizer(const World& world, const RasterizerOptions& options = {});

  // Renders `channels` of the view from `pose` (optical frame in the world) into `out`,
  // reusing its buffers. Not thread-safe per instance (it owns the z-buffer).
  void render(const runtime::PinholeCamera& camera, const Eigen::Isometry3d& pose, unsigned channels,
              CameraFrame& out);

  const WorldMesh& mesh() const { return mesh_; }
  // Triangles drawn by the last render after culling and clipping (for perf reporting).
  size_t last_triangles_drawn() const { return drawn_; }

 private:
  // A triangle, or the part of it in front of the near plane, set up for scan conversion.
  static constexpr int kMaxPolygon = 4;  // clipping a triangle at one plane adds at most a vertex
  struct Polygon {
    struct Edge {
      double ya, xa, yb, xb, slope;  // end points in pixels, the upper one first
    };
    Edge edges[kMaxPolygon];
    int n = 0;
    int j0 = 0, j1 = 0;          // rows covered, clamped to the image
    double a = 0, b = 0, c = 0;  // 1/z = a (u - cx) + b (v - cy) + c
    float wlo = 0, whi = 0;      // range of 1/z over the vertices
    uint32_t payload = 0;
  };
  // Rows per band of the z-buffer: 16 rows of 640 pixels are 80 kB of depth and payload.
  static constexpr int kBandRows = 16;

  void setup_polygon(const Eigen::Vector3d* cam, int n, const runtime::PinholeCamera& camera, double a,
                     double b, double c, uint32_t payload);
  void draw_rows(const Polygon& p, int jlo, int jhi, int band_j0, const runtime::PinholeCamera& camera);
  static uint32_t pack_labels(uint16_t cls, uint16_t instance) {
    return cls | (static_cast<uint32_t>(instance) << 16);
  }

  WorldMesh mesh_;
  RasterizerOptions options_;
  std::vector<Polygon> polygons_;        // this frame's, in drawing order
  std::vector<float> zbuf_;              // one band's 1/z, 0 = nothing
  std::vector<uint32_t> idbuf_;          // winner: its triangle index (RGB renders) or packed labels
  std::vector<uint32_t> packed_labels_;  // per triangle: class | instance << 16
  std::vector<Eigen::Vector3d> cam_vertices_;
  int width_ = 0, height_ = 0;
  size_t drawn_ = 0;
};

}  // namespace semx::simulator
