#include "semx/simulator/rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#define SEMX_RASTER_SSE2 1
#else
#define SEMX_RASTER_SSE2 0
#endif

namespace semx::simulator {
namespace {

using runtime::PinholeCamera;

// Canonical order of an edge's end points, so two triangles sharing an edge compute bitwise
// identical clip points and scan-line crossings (no cracks, no double rounding).
bool before(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if (a.z() != b.z()) return a.z() < b.z();
  if (a.x() != b.x()) return a.x() < b.x();
  return a.y() < b.y();
}

Eigen::Vector3d clip_point(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double near) {
  const Eigen::Vector3d& a = before(p, q) ? p : q;
  const Eigen::Vector3d& b = before(p, q) ? q : p;
  const double t = (near - a.z()) / (b.z() - a.z());
  Eigen::Vector3d r = a + t * (b - a);
  r.z() = near;
  return r;
}

// Sutherland-Hodgman against z >= near; a triangle gives at most 4 vertices.
int clip_near(const Eigen::Vector3d* in, int n, double near, Eigen::Vector3d* out) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = in[i];
    const Eigen::Vector3d& q = in[(i + 1) % n];
    const bool pin = p.z() >= near, qin = q.z() >= near;
    if (pin) out[m++] = p;
    if (pin != qin) out[m++] = clip_point(p, q, near);
  }
  return m;
}

}  // namespace

Rasterizer::Rasterizer(const World& world, const RasterizerOptions& options)
    : mesh_(world, options.mesh), options_(options) {
  cam_vertices_.resize(mesh_.vertices().size());
  for (size_t t = 0; t < mesh_.triangles().size(); ++t) {
    packed_labels_.push_back(pack_labels(mesh_.triangle_class()[t], mesh_.triangle_instance()[t]));
  }
}

void Rasterizer::draw_polygon(const Eigen::Vector3d* cam, int n, const PinholeCamera& camera, double a,
                              double b, double c, uint32_t payload) {
  double su[8], sv[8];
  double vmin = std::numeric_limits<double>::infinity(), vmax = -vmin, umin = vmin, umax = -vmin;
  float wlo = std::numeric_limits<float>::infinity(), whi = 0;
  for (int k = 0; k < n; ++k) {
    const double iz = 1.0 / cam[k].z();
    su[k] = camera.fx * cam[k].x() * iz + camera.cx;
    sv[k] = camera.fy * cam[k].y() * iz + camera.cy;
    vmin = std::min(vmin, sv[k]);
    vmax = std::max(vmax, sv[k]);
    umin = std::min(umin, su[k]);
    umax = std::max(umax, su[k]);
    wlo = std::min(wlo, static_cast<float>(iz));
    whi = std::max(whi, static_cast<float>(iz));
  }
  if (umax < 0 || umin > width_ - 1) return;
  const int j0 = std::max(0, static_cast<int>(std::ceil(vmin)));
  const int j1 = std::min(height_ - 1, static_cast<int>(std::floor(vmax)));
  if (j0 > j1) return;
  ++drawn_;

  struct Edge {
    double ya, xa, yb, xb, slope;
  };
  Edge edges[8];
  for (int k = 0; k < n; ++k) {
    const int l = (k + 1) % n;
    Edge e;
    const bool k_first = sv[k] < sv[l] || (sv[k] == sv[l] && su[k] <= su[l]);
    const int p = k_first ? k : l, q = k_first ? l : k;
    e.ya = sv[p];
    e.xa = su[p];
    e.yb = sv[q];
    e.xb = su[q];
    e.slope = e.yb > e.ya ? (e.xb - e.xa) / (e.yb - e.ya) : 0.0;
    edges[k] = e;
  }

  // 1/z(u, v) = a (u - cx) + b (v - cy) + c; evaluated per pixel (not accumulated) in float.
  const float fa = static_cast<float>(a);
  // Clamping to the vertices' range of 1/z guards against the huge coefficients of faces seen
  // almost edge-on; for any other face it changes nothing.
  for (int j = j0; j <= j1; ++j) {
    double xl = std::numeric_limits<double>::infinity(), xr = -xl;
    for (int k = 0; k < n; ++k) {
      const Edge& e = edges[k];
      if (j < e.ya || j > e.yb) continue;
      if (e.yb == e.ya) {
        xl = std::min({xl, e.xa, e.xb});
        xr = std::max({xr, e.xa, e.xb});
      } else {
        const double x = e.xa + (j - e.ya) * e.slope;
        xl = std::min(xl, x);
        xr = std::max(xr, x);
      }
    }
    const int i0 = std::max(0, static_cast<int>(std::ceil(xl)));
    const int i1 = std::min(width_ - 1, static_cast<int>(std::floor(xr)));
    if (i0 > i1) continue;
    const float row = static_cast<float>(c + b * (j - camera.cy) - a * camera.cx);
    float* z = zbuf_.data() + static_cast<size_t>(j) * width_;
    uint32_t* id = idbuf_.data() + static_cast<size_t>(j) * width_;
    int i = i0;
#if SEMX_RASTER_SSE2
    const __m128 va = _mm_set1_ps(fa), vrow = _mm_set1_ps(row), vlo = _mm_set1_ps(wlo),
                 vhi = _mm_set1_ps(whi);
    const __m128i vpay = _mm_set1_epi32(static_cast<int>(payload));
    __m128 vi = _mm_add_ps(_mm_set1_ps(static_cast<float>(i0)), _mm_set_ps(3.f, 2.f, 1.f, 0.f));
    const __m128 four = _mm_set1_ps(4.f);
    for (; i + 3 <= i1; i += 4) {
      const __m128 w = _mm_min_ps(vhi, _mm_max_ps(vlo, _mm_add_ps(vrow, _mm_mul_ps(va, vi))));
      const __m128 old = _mm_loadu_ps(z + i);
      const __m128 m = _mm_cmpgt_ps(w, old);
      _mm_storeu_ps(z + i, _mm_or_ps(_mm_and_ps(m, w), _mm_andnot_ps(m, old)));
      const __m128i mi = _mm_castps_si128(m);
      const __m128i oid = _mm_loadu_si128(reinterpret_cast<const __m128i*>(id + i));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(id + i),
                       _mm_or_si128(_mm_and_si128(mi, vpay), _mm_andnot_si128(mi, oid)));
      vi = _mm_add_ps(vi, four);
    }
#endif
    for (; i <= i1; ++i) {
      const float w = std::min(whi, std::max(wlo, row + fa * static_cast<float>(i)));
      if (w > z[i]) {
        z[i] = w;
        id[i] = payload;
      }
    }
  }
}

void Rasterizer::render(const PinholeCamera& camera, const Eigen::Isometry3d& pose, unsigned channels,
                        CameraFrame& out) {
  width_ = camera.width;
  height_ = camera.height;
  const size_t npx = static_cast<size_t>(width_) * height_;
  zbuf_.assign(npx, 0.0f);
  idbuf_.resize(npx);
  drawn_ = 0;

  const bool want_rgb = channels & kRenderRgb;
  const double far = std::max(camera.max_range, want_rgb ? options_.rgb_far : 0.0);
  const double near = options_.clip_near;
  const Eigen::Isometry3d T_ow = pose.inverse();
  const Eigen::Matrix3d R = T_ow.linear();
  const Eigen::Vector3d t = T_ow.translation();
  const Eigen::Vector3d eye = pose.translation();

  // Side planes of the frustum through the optical centre, one pixel wider than the image.
  const double kl = (-1.0 - camera.cx) / camera.fx, kr = (width_ - camera.cx) / camera.fx;
  const double kt = (-1.0 - camera.cy) / camera.fy, kb = (height_ - camera.cy) / camera.fy;
  const Eigen::Vector3d planes[4] = {
      Eigen::Vector3d(1, 0, -kl).normalized(), Eigen::Vector3d(-1, 0, kr).normalized(),
      Eigen::Vector3d(0, 1, -kt).normalized(), Eigen::Vector3d(0, -1, kb).normalized()};

  const auto& verts = mesh_.vertices();
  const auto& tris = mesh_.triangles();
  const auto& packed = packed_labels_;
  Eigen::Vector3d poly[3], clipped[8];
  for (const auto& range : mesh_.solids()) {
    const Eigen::Vector3d sc = R * range.sphere_center + t;
    const double r = range.sphere_radius;
    if (sc.z() + r < near || sc.z() - r > far) continue;
    bool outside = false;
    for (const auto& p : planes) outside = outside || p.dot(sc) < -r;
    if (outside) continue;
    for (uint32_t v = range.first_vertex; v < range.first_vertex + range.vertex_count; ++v) {
      cam_vertices_[v] = R * verts[v] + t;
    }
    for (uint32_t ti = range.first_triangle; ti < range.first_triangle + range.triangle_count; ++ti) {
      const auto& tr = tris[ti];
      // Back faces of closed convex solids are always hidden by their front faces.
      if (tr.normal.dot(eye) - tr.offset <= 1e-12) continue;
      poly[0] = cam_vertices_[tr.v[0]];
      poly[1] = cam_vertices_[tr.v[1]];
      poly[2] = cam_vertices_[tr.v[2]];
      const double zmin = std::min({poly[0].z(), poly[1].z(), poly[2].z()});
      const double zmax = std::max({poly[0].z(), poly[1].z(), poly[2].z()});
      if (zmax < near || zmin > far) continue;
      const Eigen::Vector3d nc = R * tr.normal;
      const double dc = tr.offset + nc.dot(t);  // plane in the optical frame: nc · p = dc (< 0)
      const double a = nc.x() / (camera.fx * dc), b = nc.y() / (camera.fy * dc), c = nc.z() / dc;
      // Without RGB the buffer holds the labels themselves, which spares the resolve a lookup.
      const uint32_t payload = want_rgb ? ti : packed[ti];
      if (zmin >= near) {
        draw_polygon(poly, 3, camera, a, b, c, payload);
      } else {
        const int m = clip_near(poly, 3, near, clipped);
        if (m >= 3) draw_polygon(clipped, m, camera, a, b, c, payload);
      }
    }
  }

  out.camera = camera;
  out.pose = pose;
  out.channels = channels;
  const float wmax_range = static_cast<float>(1.0 / camera.max_range);
  if (channels & kRenderDepth) {
    out.depth.resize(width_, height_);
    resolve_depth(camera, out.depth.data.data(), npx);
  }
  if (channels & kRenderLabels) {
    out.class_label.resize(width_, height_);
    out.instance_label.resize(width_, height_);
    uint16_t* lc = out.class_label.data.data();
    uint16_t* li = out.instance_label.data.data();
    for (size_t i = 0; i < npx; ++i) {
      const uint32_t lab = zbuf_[i] >= wmax_range ? (want_rgb ? packed_labels_[idbuf_[i]] : idbuf_[i]) : 0u;
      lc[i] = static_cast<uint16_t>(lab & 0xFFFFu);
      li[i] = static_cast<uint16_t>(lab >> 16);
    }
  }
  if (want_rgb) {
    out.rgb.resize(width_, height_);
    const float wfar = static_cast<float>(1.0 / far);
    const auto& rgb = mesh_.triangle_rgb();
    Rgb* o = out.rgb.data.data();
    for (size_t i = 0; i < npx; ++i) o[i] = zbuf_[i] >= wfar ? rgb[idbuf_[i]] : kBackgroundRgb;
  }
}

void Rasterizer::resolve_depth(const PinholeCamera& camera, uint16_t* d, size_t npx) const {
  const float wmax_range = static_cast<float>(1.0 / camera.max_range);
  const float zmin_mm = static_cast<float>(camera.min_range * 1000.0);
  size_t i = 0;
#if SEMX_RASTER_SSE2
  // Eight pixels at a time; uint16 packing goes through a signed pack with a 32768 offset (SSE2
  // has no unsigned 32->16 pack).
  const __m128 k1000 = _mm_set1_ps(1000.f), tiny = _mm_set1_ps(1e-20f), half = _mm_set1_ps(0.5f);
  const __m128 cap = _mm_set1_ps(65534.f), vmin = _mm_set1_ps(zmin_mm), vfar = _mm_set1_ps(wmax_range);
  const __m128i noret = _mm_set1_epi32(runtime::kDepthNoReturn), off = _mm_set1_epi32(32768);
  const __m128i flip = _mm_set1_epi16(static_cast<short>(0x8000));
  auto four = [&](const float* zp) {
    const __m128 w = _mm_loadu_ps(zp);
    const __m128 mm = _mm_div_ps(k1000, _mm_max_ps(w, tiny));
    __m128i v = _mm_cvttps_epi32(_mm_min_ps(_mm_add_ps(mm, half), cap));
    v = _mm_andnot_si128(_mm_castps_si128(_mm_cmplt_ps(mm, vmin)), v);  // below min range: invalid (0)
    const __m128i far = _mm_castps_si128(_mm_cmplt_ps(w, vfar));
    v = _mm_or_si128(_mm_and_si128(far, noret), _mm_andnot_si128(far, v));
    return _mm_sub_epi32(v, off);
  };
  for (; i + 8 <= npx; i += 8) {
    const __m128i packed = _mm_xor_si128(_mm_packs_epi32(four(&zbuf_[i]), four(&zbuf_[i + 4])), flip);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(d + i), packed);
  }
#endif
  for (; i < npx; ++i) {
    const float w = zbuf_[i];
    const float mm = 1000.0f / std::max(w, 1e-20f);
    uint16_t v = static_cast<uint16_t>(std::min(mm + 0.5f, 65534.0f));
    v = mm < zmin_mm ? runtime::kDepthInvalid : v;
    // The same test as the labels', so a pixel has a label exactly when it has a return.
    d[i] = w < wmax_range ? runtime::kDepthNoReturn : v;
  }
}

}  // namespace semx::simulator
