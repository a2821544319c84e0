#include "semx/simulator/rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
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

// n copies of c: 16 pixels are 48 bytes, three vector stores, where a loop of 3-byte stores
// would cost a cycle or more per pixel.
void fill_rgb(Rgb* o, size_t n, Rgb c) {
  size_t k = 0;
#if SEMX_RASTER_SSE2
  if (n >= 16) {
    alignas(16) uint8_t pattern[48];
    for (int p = 0; p < 16; ++p) {
      pattern[3 * p] = c.r;
      pattern[3 * p + 1] = c.g;
      pattern[3 * p + 2] = c.b;
    }
    // Loaded into registers once: stores through `o` may alias anything byte-sized, and
    // re-reading the pattern after each would stall on the stores just made.
    const __m128i p0 = _mm_load_si128(reinterpret_cast<const __m128i*>(pattern));
    const __m128i p1 = _mm_load_si128(reinterpret_cast<const __m128i*>(pattern + 16));
    const __m128i p2 = _mm_load_si128(reinterpret_cast<const __m128i*>(pattern + 32));
    uint8_t* bytes = reinterpret_cast<uint8_t*>(o);
    for (; k + 16 <= n; k += 16) {
      _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + 3 * k), p0);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + 3 * k + 16), p1);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + 3 * k + 32), p2);
    }
  }
#endif
  for (; k < n; ++k) o[k] = c;
}

// Pixels i and j resolve alike when they pass the same visibility limits and, if they pass
// either, hold the same payload. Pixels that fail both (nothing drawn, or beyond range) hold
// payloads that are stale or never looked up, so they do not break a run.
struct RunKey {
  uint32_t id;
  bool lab, rgb;
  RunKey(const uint32_t* ids, const float* z, size_t i, float wlab, float wrgb)
      : id(ids[i]), lab(z[i] >= wlab), rgb(z[i] >= wrgb) {}
  bool matches(const uint32_t* ids, const float* z, size_t j, float wlab, float wrgb) const {
    return (z[j] >= wlab) == lab && (z[j] >= wrgb) == rgb && (ids[j] == id || !(lab || rgb));
  }
};

// End of the run of pixels from i on that resolve like pixel i.
size_t run_end(const uint32_t* ids, const float* z, size_t i, size_t npx, float wlab, float wrgb) {
  const RunKey key(ids, z, i, wlab, wrgb);
  size_t j = i + 1;
#if SEMX_RASTER_SSE2
  const __m128i vid = _mm_set1_epi32(static_cast<int>(key.id));
  const __m128 lab = _mm_set1_ps(wlab), rgb = _mm_set1_ps(wrgb);
  // Per lane, all ones where the first pixel passes a limit: XOR with a lane's test leaves the
  // sign bit set exactly where the two disagree.
  const __m128 lab0 = _mm_castsi128_ps(_mm_set1_epi32(key.lab ? -1 : 0));
  const __m128 rgb0 = _mm_castsi128_ps(_mm_set1_epi32(key.rgb ? -1 : 0));
  const __m128 any_id = _mm_castsi128_ps(_mm_set1_epi32(key.lab || key.rgb ? 0 : -1));
  auto differ = [&](size_t at) {
    const __m128 w = _mm_loadu_ps(z + at);
    const __m128i id = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + at));
    const __m128 same_id = _mm_or_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(id, vid)), any_id);
    const __m128 vis =
        _mm_or_ps(_mm_xor_ps(_mm_cmpge_ps(w, lab), lab0), _mm_xor_ps(_mm_cmpge_ps(w, rgb), rgb0));
    return _mm_movemask_ps(_mm_andnot_ps(same_id, _mm_castsi128_ps(_mm_set1_epi32(-1)))) |
           _mm_movemask_ps(vis);
  };
  for (; j + 8 <= npx; j += 8) {
    const int bad = differ(j) | differ(j + 4) << 4;
    if (bad) return j + static_cast<size_t>(__builtin_ctz(static_cast<unsigned>(bad)));
  }
#endif
  while (j < npx && key.matches(ids, z, j, wlab, wrgb)) ++j;
  return j;
}

// Turns payloads into labels and RGB. A visible face covers a run of pixels in a row with one
// payload, so the payload is looked up once per run, and the outputs are filled span by span
// (runs that resolve to the same labels and colour, like the two triangles of a wall, make one
// span) rather than pixel by pixel. Bands are fed in order; a span may continue across them.
class PayloadResolver {
 public:
  // A pixel is labelled when its 1/z >= wlab and coloured when >= wrgb. `labels`, `rgb` and
  // `runs` may be null (that output is not wanted).
  PayloadResolver(float wlab, float wrgb, bool payload_is_triangle, const uint32_t* packed_labels,
                  const Rgb* triangle_rgb, CameraFrame* labels, Rgb* rgb, std::vector<RgbRun>* runs)
      : wlab_(wlab),
        wrgb_(wrgb),
        payload_is_triangle_(payload_is_triangle),
        packed_(packed_labels),
        tri_rgb_(triangle_rgb),
        lc_(labels ? labels->class_label.data.data() : nullptr),
        li_(labels ? labels->instance_label.data.data() : nullptr),
        rgb_(rgb),
        runs_(runs) {
    if (runs_) runs_->clear();
  }

  // Pixels [first, first + n) of the image, whose payloads and 1/z are ids[0, n) and z[0, n).
  void add(const uint32_t* ids, const float* z, size_t first, size_t n) {
    for (size_t i = 0; i < n;) {
      const size_t j = run_end(ids, z, i, n, wlab_, wrgb_);
      const uint32_t id = ids[i];
      const uint32_t lab = lc_ && z[i] >= wlab_ ? (payload_is_triangle_ ? packed_[id] : id) : 0u;
      const Rgb col = (rgb_ || runs_) && z[i] >= wrgb_ ? tri_rgb_[id] : kBackgroundRgb;
      if (first + i > start_ && (lab != lab_ || col != col_)) flush(first + i);
      lab_ = lab;
      col_ = col;
      i = j;
    }
    end_ = first + n;
  }
  void finish() { flush(end_); }

 private:
  // Writes the pending span [start_, end).
  void flush(size_t end) {
    if (lc_) {
      std::fill(lc_ + start_, lc_ + end, static_cast<uint16_t>(lab_ & 0xFFFFu));
      std::fill(li_ + start_, li_ + end, static_cast<uint16_t>(lab_ >> 16));
    }
    if (rgb_) fill_rgb(rgb_ + start_, end - start_, col_);
    if (runs_ && end > start_) {
      // Spans differ in labels or colour; runs only in colour.
      if (!runs_->empty() && runs_->back().colour == col_) {
        runs_->back().length += static_cast<uint32_t>(end - start_);
      } else {
        runs_->push_back({static_cast<uint32_t>(end - start_), col_});
      }
    }
    start_ = end;
  }

  float wlab_, wrgb_;
  bool payload_is_triangle_;
  const uint32_t* packed_;
  const Rgb* tri_rgb_;
  uint16_t* lc_;
  uint16_t* li_;
  Rgb* rgb_;
  std::vector<RgbRun>* runs_;
  size_t start_ = 0, end_ = 0;  // the pending span starts at start_; pixels before end_ are added
  uint32_t lab_ = 0;
  Rgb col_ = kBackgroundRgb;
};

// 1/z to depth in millimetres, with the range limits of the camera.
void resolve_depth(const PinholeCamera& camera, const float* z, uint16_t* d, size_t npx) {
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
    const __m128i packed = _mm_xor_si128(_mm_packs_epi32(four(z + i), four(z + i + 4)), flip);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(d + i), packed);
  }
#endif
  for (; i < npx; ++i) {
    const float w = z[i];
    const float mm = 1000.0f / std::max(w, 1e-20f);
    uint16_t v = static_cast<uint16_t>(std::min(mm + 0.5f, 65534.0f));
    v = mm < zmin_mm ? runtime::kDepthInvalid : v;
    // The same test as the labels', so a pixel has a label exactly when it has a return.
    d[i] = w < wmax_range ? runtime::kDepthNoReturn : v;
  }
}

}  // namespace

Rasterizer::Rasterizer(const World& world, const RasterizerOptions& options)
    : mesh_(world, options.mesh), options_(options) {
  cam_vertices_.resize(mesh_.vertices().size());
  for (size_t t = 0; t < mesh_.triangles().size(); ++t) {
    packed_labels_.push_back(pack_labels(mesh_.triangle_class()[t], mesh_.triangle_instance()[t]));
  }
}

void Rasterizer::setup_polygon(const Eigen::Vector3d* cam, int n, const PinholeCamera& camera, double a,
                               double b, double c, uint32_t payload) {
  double su[kMaxPolygon], sv[kMaxPolygon];
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

  Polygon& p = polygons_.emplace_back();
  p.n = n;
  p.j0 = j0;
  p.j1 = j1;
  p.a = a;
  p.b = b;
  p.c = c;
  p.wlo = wlo;
  p.whi = whi;
  p.payload = payload;
  for (int k = 0; k < n; ++k) {
    const int l = (k + 1) % n;
    Polygon::Edge& e = p.edges[k];
    const bool k_first = sv[k] < sv[l] || (sv[k] == sv[l] && su[k] <= su[l]);
    const int first = k_first ? k : l, second = k_first ? l : k;
    e.ya = sv[first];
    e.xa = su[first];
    e.yb = sv[second];
    e.xb = su[second];
    e.slope = e.yb > e.ya ? (e.xb - e.xa) / (e.yb - e.ya) : 0.0;
  }
}

void Rasterizer::draw_rows(const Polygon& p, int jlo, int jhi, int band_j0, const PinholeCamera& camera) {
  // 1/z(u, v) = a (u - cx) + b (v - cy) + c; evaluated per pixel (not accumulated) in float.
  const float fa = static_cast<float>(p.a);
  const float wlo = p.wlo, whi = p.whi;
  // Clamping to the vertices' range of 1/z guards against the huge coefficients of faces seen
  // almost edge-on; for any other face it changes nothing.
  for (int j = jlo; j <= jhi; ++j) {
    double xl = std::numeric_limits<double>::infinity(), xr = -xl;
    for (int k = 0; k < p.n; ++k) {
      const Polygon::Edge& e = p.edges[k];
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
    const float row = static_cast<float>(p.c + p.b * (j - camera.cy) - p.a * camera.cx);
    float* z = zbuf_.data() + static_cast<size_t>(j - band_j0) * width_;
    uint32_t* id = idbuf_.data() + static_cast<size_t>(j - band_j0) * width_;
    int i = i0;
#if SEMX_RASTER_SSE2
    const __m128 va = _mm_set1_ps(fa), vrow = _mm_set1_ps(row), vlo = _mm_set1_ps(wlo),
                 vhi = _mm_set1_ps(whi);
    const __m128i vpay = _mm_set1_epi32(static_cast<int>(p.payload));
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
        id[i] = p.payload;
      }
    }
  }
}

void Rasterizer::render(const PinholeCamera& camera, const Eigen::Isometry3d& pose, unsigned channels,
                        CameraFrame& out) {
  width_ = camera.width;
  height_ = camera.height;
  drawn_ = 0;
  polygons_.clear();

  const bool want_rgb = channels & (kRenderRgb | kRenderRgbRuns);
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
  Eigen::Vector3d poly[3], clipped[kMaxPolygon];
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
        setup_polygon(poly, 3, camera, a, b, c, payload);
      } else {
        const int m = clip_near(poly, 3, near, clipped);
        if (m >= 3) setup_polygon(clipped, m, camera, a, b, c, payload);
      }
    }
  }

  out.camera = camera;
  out.pose = pose;
  out.channels = channels;
  if (channels & kRenderDepth) out.depth.resize(width_, height_);
  if (channels & kRenderLabels) {
    out.class_label.resize(width_, height_);
    out.instance_label.resize(width_, height_);
  }
  if (channels & kRenderRgb) out.rgb.resize(width_, height_);

  // The image is drawn and resolved a band of rows at a time: a band's depth and payload
  // buffers stay in cache from clearing through drawing to resolving, where whole-image buffers
  // (2.4 MB at 640x480) would leave it between passes (a few per cent of the render time on the
  // development machine). Every pixel still sees the polygons in the same order, so the result
  // does not depend on the band height.
  const size_t band_px = static_cast<size_t>(kBandRows) * width_;
  zbuf_.resize(band_px);
  idbuf_.resize(band_px);
  PayloadResolver payloads(static_cast<float>(1.0 / camera.max_range), static_cast<float>(1.0 / far),
                           want_rgb, packed_labels_.data(), mesh_.triangle_rgb().data(),
                           (channels & kRenderLabels) ? &out : nullptr,
                           (channels & kRenderRgb) ? out.rgb.data.data() : nullptr,
                           (channels & kRenderRgbRuns) ? &out.rgb_runs : nullptr);
  for (int b0 = 0; b0 < height_; b0 += kBandRows) {
    const int b1 = std::min(height_, b0 + kBandRows) - 1;
    const size_t first = static_cast<size_t>(b0) * width_, n = static_cast<size_t>(b1 - b0 + 1) * width_;
    std::fill(zbuf_.begin(), zbuf_.begin() + static_cast<std::ptrdiff_t>(n), 0.0f);
    for (const Polygon& p : polygons_) {
      if (p.j1 >= b0 && p.j0 <= b1) draw_rows(p, std::max(p.j0, b0), std::min(p.j1, b1), b0, camera);
    }
    if (channels & kRenderDepth) resolve_depth(camera, zbuf_.data(), out.depth.data.data() + first, n);
    if (channels & (kRenderLabels | kRenderRgb | kRenderRgbRuns))
      payloads.add(idbuf_.data(), zbuf_.data(), first, n);
  }
  payloads.finish();
}

}  // namespace semx::simulator
