// ods_render.cpp: ODS panoramas by ray casting (reference) and by the paper's tessellate-project-
// split-rasterise pipeline (omnidirectional-stereo.txt §3-4, Alg. 1, Eq. 1-6). See
// vislib/render/ods_render.h for the contracts and runtime/ods.h for the pure functions.
#include "vislib/render/ods_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>

namespace vislib {

namespace {

using pvs_runtime::Eye;
using pvs_runtime::LonLat;
using pvs_runtime::Point3;

Point3 to_point(Vec3 v) {
  return {v.x, v.y, v.z};
}
Vec3 to_vec(const Point3& p) {
  return {p.x, p.y, p.z};
}

uint8_t to_byte(double v) {
  const double s = std::round(v * 255.0);
  return uint8_t(s < 0 ? 0 : (s > 255 ? 255 : s));
}

Frame empty_frame(int w, int h) {
  Frame f;
  f.width = w;
  f.height = h;
  const size_t n = f.pixel_count();
  f.rgb.assign(3 * n, 0);
  f.depth.assign(n, std::numeric_limits<float>::infinity());
  f.tri.assign(n, kNoHit);
  return f;
}

// Fills rgb from tri with the pixel-centre direction of each pixel.
void shade_frame(const Scene& scene, Frame& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, f.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < f.width; ++x) {
        const size_t p = size_t(y) * size_t(f.width) + size_t(x);
        uint8_t* out = &f.rgb[3 * p];
        if (f.tri[p] == kNoHit) {
          out[0] = kRenderBackground[0], out[1] = kRenderBackground[1],
          out[2] = kRenderBackground[2];
          continue;
        }
        const LonLat ll = pvs_runtime::pixel_to_lonlat(x + 0.5, y + 0.5, f.width, f.height);
        const auto c = shade_triangle(scene, f.tri[p], to_vec(pvs_runtime::lonlat_direction(ll)));
        out[0] = c[0], out[1] = c[1], out[2] = c[2];
      }
  });
}

// An image-space triangle: pixel coordinates (u = column, v = row, continuous), range per vertex.
struct ImgTri {
  std::array<float, 3> u, v, r;
  uint32_t tri;
};

constexpr int kBandRows = 8;

// Horizontal (x-z) distance from the axis through c to segment ab.
double axis_segment_distance(const Point3& c, const Point3& a, const Point3& b) {
  const double ax = a.x - c.x, az = a.z - c.z, dx = b.x - a.x, dz = b.z - a.z;
  const double len2 = dx * dx + dz * dz;
  const double t = len2 > 0 ? std::clamp(-(ax * dx + az * dz) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(ax + t * dx, az + t * dz);
}

// Turns small (tessellated) triangles into image-space triangles for one eye.
struct Emitter {
  struct Vtx {
    Point3 p;
    pvs_runtime::OdsProjection pr;
    double lon_c = 0;  // longitude seen from the centre
  };

  const Point3& c;
  const OdsSettings& s;
  Eye eye;
  bool exact;
  int W, H;
  uint32_t tri;
  std::vector<ImgTri>& dst;
  OdsRasterStats& st;

  Vtx make(const Point3& p) const {
    Vtx v;
    v.p = p;
    v.pr = exact ? pvs_runtime::ods_project_exact(p, c, s.ipd, eye, s.merge)
                 : pvs_runtime::ods_project_paper(p, c, s.ipd, eye, s.merge);
    v.lon_c = pvs_runtime::direction_lonlat({p.x - c.x, p.y - c.y, p.z - c.z}).lon;
    return v;
  }

  // Projects, splits at the seam and (if the axis crosses it) the pole, and appends.
  void draw(const Vtx& a, const Vtx& b, const Vtx& d) {
    const pvs_runtime::AxisCrossing ax = pvs_runtime::axis_crossing({a.p, b.p, d.p}, c);
    int pole = 0;
    double pole_range = 0;
    if (ax.crosses) {
      ++st.pole_triangles;
      pole = ax.pole;
      pole_range = std::fabs(ax.point.y - c.y);
    }
    const std::array<pvs_runtime::ProjVertex, 3> pv{
        pvs_runtime::ProjVertex{a.pr.ll.lon, a.pr.ll.lat, a.pr.range, a.lon_c},
        pvs_runtime::ProjVertex{b.pr.ll.lon, b.pr.ll.lat, b.pr.range, b.lon_c},
        pvs_runtime::ProjVertex{d.pr.ll.lon, d.pr.ll.lat, d.pr.range, d.lon_c}};
    for (const pvs_runtime::ProjTriangle& pt : pvs_runtime::split_seam_pole(pv, pole, pole_range)) {
      ImgTri out;
      out.tri = tri;
      for (size_t i = 0; i < 3; ++i) {
        const auto px = pvs_runtime::lonlat_to_pixel({pt.v[i].lon, pt.v[i].lat}, W, H);
        out.u[i] = float(px[0]);
        out.v[i] = float(px[1]);
        out.r[i] = float(pt.v[i].range);
      }
      dst.push_back(out);
    }
  }

  // The visible point of segment from visible v to invisible w nearest the visibility boundary.
  Vtx boundary(const Vtx& v, const Vtx& w) const {
    double lo = 0, hi = 1;  // lo visible, hi not
    Vtx best = v;
    for (int k = 0; k < 48; ++k) {
      const double t = 0.5 * (lo + hi);
      const Vtx m = make(
          {v.p.x + t * (w.p.x - v.p.x), v.p.y + t * (w.p.y - v.p.y), v.p.z + t * (w.p.z - v.p.z)});
      if (m.pr.visible) {
        lo = t;
        best = m;
      } else {
        hi = t;
      }
    }
    return best;
  }

  // The exact projection near the viewing disc (radius ipd/2 about the axis; inside it no ODS ray
  // passes): an edge is halved while it comes within ipd/2 of the axis and is longer than
  // ipd/32. The rule looks at the edge alone, so both triangles sharing an edge split it alike
  // (no cracks). A triangle with no edge to split is drawn if all its vertices are visible;
  // else its visible part (the polygon of its visible vertices and the boundary points on its
  // edges, which project onto the pole row) is drawn, or nothing if the axis crosses it.
  bool split_edge(const Vtx& u, const Vtx& v) const {
    const double hmax = 0.5 * s.ipd;
    const double len =
        std::sqrt((u.p.x - v.p.x) * (u.p.x - v.p.x) + (u.p.y - v.p.y) * (u.p.y - v.p.y) +
                  (u.p.z - v.p.z) * (u.p.z - v.p.z));
    return hmax > 0 && len > hmax / 16 && axis_segment_distance(c, u.p, v.p) <= hmax;
  }
  Vtx mid(const Vtx& u, const Vtx& v) const {
    return make({(u.p.x + v.p.x) / 2, (u.p.y + v.p.y) / 2, (u.p.z + v.p.z) / 2});
  }
  void exact_triangle(const Vtx& a, const Vtx& b, const Vtx& d, int depth) {
    const std::array<const Vtx*, 3> v{&a, &b, &d};
    std::array<bool, 3> split{};  // split[i]: edge v[i] -> v[i+1]
    int nsplit = 0;
    if (depth < 40)
      for (size_t i = 0; i < 3; ++i) nsplit += split[i] = split_edge(*v[i], *v[(i + 1) % 3]);
    if (nsplit == 3) {
      const Vtx ab = mid(a, b), bd = mid(b, d), da = mid(d, a);
      exact_triangle(a, ab, da, depth + 1);
      exact_triangle(ab, b, bd, depth + 1);
      exact_triangle(da, bd, d, depth + 1);
      exact_triangle(ab, bd, da, depth + 1);
      return;
    }
    if (nsplit == 1) {
      const size_t i = split[0] ? 0 : (split[1] ? 1 : 2);
      const Vtx &p = *v[i], &q = *v[(i + 1) % 3], &r = *v[(i + 2) % 3];
      const Vtx m = mid(p, q);
      exact_triangle(p, m, r, depth + 1);
      exact_triangle(m, q, r, depth + 1);
      return;
    }
    if (nsplit == 2) {
      const size_t k = !split[0] ? 0 : (!split[1] ? 1 : 2);  // the edge kept: v[k] -> v[k+1]
      const Vtx &p = *v[k], &q = *v[(k + 1) % 3], &r = *v[(k + 2) % 3];
      const Vtx m1 = mid(q, r), m2 = mid(r, p);  // split edges q -> r and r -> p
      exact_triangle(m1, r, m2, depth + 1);
      exact_triangle(p, q, m1, depth + 1);
      exact_triangle(p, m1, m2, depth + 1);
      return;
    }
    const int nvis = int(a.pr.visible) + int(b.pr.visible) + int(d.pr.visible);
    if (nvis == 3) return draw(a, b, d);
    if (nvis == 0 || pvs_runtime::axis_crossing({a.p, b.p, d.p}, c).crosses) {
      ++st.dropped_inside_circle;
      return;
    }
    std::vector<Vtx> poly;
    for (size_t i = 0; i < 3; ++i) {
      const Vtx& p = *v[i];
      const Vtx& q = *v[(i + 1) % 3];
      if (p.pr.visible) poly.push_back(p);
      if (p.pr.visible != q.pr.visible)
        poly.push_back(p.pr.visible ? boundary(p, q) : boundary(q, p));
    }
    for (size_t k = 1; k + 1 < poly.size(); ++k) draw(poly[0], poly[k], poly[k + 1]);
  }
};

}  // namespace

Frame render_ods_rays(const Scene& scene, const EmbreeScene& rt, const OdsSettings& s, Eye eye,
                      const uint8_t* allowed) {
  assert(rt.triangle_count() == scene.triangle_count());
  assert(s.width >= 2 && s.height >= 1 && s.ipd >= 0);
  Frame f = empty_frame(s.width, s.height);
  const size_t w = size_t(s.width);
  const Point3 c = to_point(s.centre);
  tbb::parallel_for(tbb::blocked_range<int>(0, s.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<Vec3> eyes(w), dirs(w);
    std::vector<Hit> hits(w);
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < s.width; ++x) {
        const pvs_runtime::Ray r =
            pvs_runtime::ods_pixel_ray(x, y, s.width, s.height, c, s.ipd, eye, s.merge);
        eyes[size_t(x)] = to_vec(r.origin);
        dirs[size_t(x)] = to_vec(r.direction);
      }
      rt.first_hits_from(eyes.data(), dirs.data(), w, s.z_near, allowed, hits.data());
      for (size_t x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        if (hits[x].tri == kNoHit) continue;
        f.tri[p] = hits[x].tri;
        f.depth[p] = float(hits[x].lambda);  // unit direction: lambda is the range
      }
    }
  });
  shade_frame(scene, f);
  return f;
}

Frame render_ods_raster(const Scene& scene, const std::vector<uint32_t>& ids, const OdsSettings& s,
                        Eye eye, const OdsRasterSettings& raster, OdsRasterStats* stats) {
  assert(s.width >= 2 && s.height >= 1 && s.ipd >= 0);
  assert(raster.static_level >= 0 && raster.static_level <= 64);
  const int W = s.width, H = s.height;
  const Point3 c = to_point(s.centre);
  const bool exact = raster.formula == OdsFormula::Exact;

  // Phase 1: tessellate, project, split; fixed chunks of input triangles (not thread-dependent).
  constexpr size_t kChunk = 256;
  const size_t chunks = (ids.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<ImgTri>> out(chunks);
  std::vector<OdsRasterStats> chunk_stats(chunks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks), [&](const tbb::blocked_range<size_t>&
                                                                   range) {
    std::map<std::array<int, 4>, pvs_runtime::Tessellation> cache;
    std::vector<Point3> world;
    std::vector<pvs_runtime::OdsProjection> proj;
    std::vector<double> lon_c;
    for (size_t ch = range.begin(); ch != range.end(); ++ch) {
      OdsRasterStats& st = chunk_stats[ch];
      std::vector<ImgTri>& dst = out[ch];
      for (size_t k = ch * kChunk; k < std::min(ids.size(), (ch + 1) * kChunk); ++k) {
        const uint32_t t = ids[k];
        ++st.input_triangles;
        const auto corners = scene.corners(t, 0);
        const std::array<Point3, 3> p{to_point(corners[0]), to_point(corners[1]),
                                      to_point(corners[2])};
        std::array<int, 4> key;
        if (raster.static_level > 0) {
          key = {raster.static_level, raster.static_level, raster.static_level,
                 raster.static_level};
        } else {
          // Alg. 1 from the mono (centre) projection of the vertices and opposite-edge midpoints.
          std::array<LonLat, 3> pl, ml;
          for (int i = 0; i < 3; ++i) {
            const Point3& a = p[size_t((i + 1) % 3)];
            const Point3& b = p[size_t((i + 2) % 3)];
            pl[size_t(i)] = pvs_runtime::direction_lonlat(
                {p[size_t(i)].x - c.x, p[size_t(i)].y - c.y, p[size_t(i)].z - c.z});
            const Point3 mid{(a.x + b.x) / 2 - c.x, (a.y + b.y) / 2 - c.y, (a.z + b.z) / 2 - c.z};
            ml[size_t(i)] = pvs_runtime::direction_lonlat(mid);
          }
          const pvs_runtime::TessLevels lv = pvs_runtime::tessellation_levels(pl, ml);
          key = {int(std::ceil(lv.outer[0])), int(std::ceil(lv.outer[1])),
                 int(std::ceil(lv.outer[2])), int(std::ceil(lv.inner))};
        }
        auto it = cache.find(key);
        if (it == cache.end())
          it =
              cache.emplace(key, pvs_runtime::tessellate_triangle({key[0], key[1], key[2]}, key[3]))
                  .first;
        const pvs_runtime::Tessellation& tess = it->second;
        world.resize(tess.points.size());
        proj.resize(tess.points.size());
        lon_c.resize(tess.points.size());
        for (size_t q = 0; q < tess.points.size(); ++q) {
          const auto& w = tess.points[q];
          // Summed in this order so a point on a shared edge is bit-identical from both sides.
          world[q] = {(w[0] * p[0].x + w[1] * p[1].x) + w[2] * p[2].x,
                      (w[0] * p[0].y + w[1] * p[1].y) + w[2] * p[2].y,
                      (w[0] * p[0].z + w[1] * p[1].z) + w[2] * p[2].z};
          lon_c[q] =
              pvs_runtime::direction_lonlat({world[q].x - c.x, world[q].y - c.y, world[q].z - c.z})
                  .lon;
          const bool at_centre = world[q].x == c.x && world[q].y == c.y && world[q].z == c.z;
          if (at_centre) {
            proj[q] = pvs_runtime::OdsProjection{};
          } else {
            proj[q] = exact ? pvs_runtime::ods_project_exact(world[q], c, s.ipd, eye, s.merge)
                            : pvs_runtime::ods_project_paper(world[q], c, s.ipd, eye, s.merge);
          }
        }
        st.tessellated += tess.triangles.size();
        Emitter em{c, s, eye, exact, W, H, t, dst, st};
        for (const auto& tri : tess.triangles) {
          const Emitter::Vtx a{world[tri[0]], proj[tri[0]], lon_c[tri[0]]};
          const Emitter::Vtx b{world[tri[1]], proj[tri[1]], lon_c[tri[1]]};
          const Emitter::Vtx d{world[tri[2]], proj[tri[2]], lon_c[tri[2]]};
          if (exact)
            em.exact_triangle(a, b, d, 0);
          else
            em.draw(a, b, d);
        }
      }
      st.drawn = dst.size();
    }
  });
  OdsRasterStats total;
  for (const OdsRasterStats& st : chunk_stats) {
    total.input_triangles += st.input_triangles;
    total.tessellated += st.tessellated;
    total.drawn += st.drawn;
    total.pole_triangles += st.pole_triangles;
    total.dropped_inside_circle += st.dropped_inside_circle;
  }
  if (stats) *stats = total;

  // Phase 2: bin into bands of kBandRows rows (in chunk order: deterministic).
  std::vector<ImgTri> all;
  all.reserve(total.drawn);
  for (auto& v : out) {
    all.insert(all.end(), v.begin(), v.end());
    std::vector<ImgTri>().swap(v);
  }
  const int bands = (H + kBandRows - 1) / kBandRows;
  std::vector<std::vector<uint32_t>> band_tris(static_cast<size_t>(bands));
  for (size_t i = 0; i < all.size(); ++i) {
    const ImgTri& t = all[i];
    const double vmin = std::min({t.v[0], t.v[1], t.v[2]}),
                 vmax = std::max({t.v[0], t.v[1], t.v[2]});
    const double umin = std::min({t.u[0], t.u[1], t.u[2]}),
                 umax = std::max({t.u[0], t.u[1], t.u[2]});
    if (umax < 0 || umin > W) continue;
    const int y0 = std::max(0, int(std::ceil(vmin - 0.5))),
              y1 = std::min(H - 1, int(std::floor(vmax - 0.5)));
    if (y0 > y1) continue;
    for (int b = y0 / kBandRows; b <= y1 / kBandRows; ++b)
      band_tris[size_t(b)].push_back(uint32_t(i));
  }

  // Phase 3: rasterise each band; depth ties go to the lower triangle id (order-independent).
  Frame f = empty_frame(W, H);
  tbb::parallel_for(tbb::blocked_range<int>(0, bands), [&](const tbb::blocked_range<int>& br) {
    for (int b = br.begin(); b != br.end(); ++b) {
      const int row0 = b * kBandRows, row1 = std::min(H, row0 + kBandRows) - 1;
      for (uint32_t i : band_tris[size_t(b)]) {
        const ImgTri& t = all[i];
        double ax = t.u[0], ay = t.v[0], bx = t.u[1], by = t.v[1], cx = t.u[2], cy = t.v[2];
        double ra = t.r[0], rb = t.r[1], rc = t.r[2];
        double area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
        if (area == 0 || !std::isfinite(area)) continue;
        if (area < 0) {
          std::swap(bx, cx), std::swap(by, cy), std::swap(rb, rc);
          area = -area;
        }
        // Top-left rule: on an edge (E = 0) a pixel belongs to the edge whose direction has
        // dy > 0, or dy = 0 and dx < 0; the neighbour traverses the edge the other way.
        auto owns = [](double x0, double y0, double x1, double y1) {
          const double dx = x1 - x0, dy = y1 - y0;
          return dy > 0 || (dy == 0 && dx < 0);
        };
        const bool o_ab = owns(ax, ay, bx, by), o_bc = owns(bx, by, cx, cy),
                   o_ca = owns(cx, cy, ax, ay);
        const int x0 = std::max(0, int(std::ceil(std::min({ax, bx, cx}) - 0.5)));
        const int x1 = std::min(W - 1, int(std::floor(std::max({ax, bx, cx}) - 0.5)));
        const int y0 = std::max(row0, int(std::ceil(std::min({ay, by, cy}) - 0.5)));
        const int y1 = std::min(row1, int(std::floor(std::max({ay, by, cy}) - 0.5)));
        for (int y = y0; y <= y1; ++y) {
          const double py = y + 0.5;
          for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5;
            const double e_ab = (bx - ax) * (py - ay) - (by - ay) * (px - ax);  // weight of c
            const double e_bc = (cx - bx) * (py - by) - (cy - by) * (px - bx);  // weight of a
            const double e_ca = (ax - cx) * (py - cy) - (ay - cy) * (px - cx);  // weight of b
            if (e_ab < 0 || e_bc < 0 || e_ca < 0) continue;
            if ((e_ab == 0 && !o_ab) || (e_bc == 0 && !o_bc) || (e_ca == 0 && !o_ca)) continue;
            const float range = float((e_bc * ra + e_ca * rb + e_ab * rc) / area);
            if (!(range > s.z_near)) continue;
            const size_t p = size_t(y) * size_t(W) + size_t(x);
            if (range < f.depth[p] || (range == f.depth[p] && t.tri < f.tri[p])) {
              f.depth[p] = range;
              f.tri[p] = t.tri;
            }
          }
        }
      }
    }
  });
  shade_frame(scene, f);
  return f;
}

std::vector<uint8_t> pack_top_bottom(const Frame& left, const Frame& right) {
  assert(left.width == right.width && left.height == right.height);
  std::vector<uint8_t> rgb(left.rgb);
  rgb.insert(rgb.end(), right.rgb.begin(), right.rgb.end());
  return rgb;
}

namespace {
double luma(const uint8_t* p) {
  return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
}
}  // namespace

std::vector<uint8_t> anaglyph(const Frame& left, const Frame& right) {
  assert(left.width == right.width && left.height == right.height);
  std::vector<uint8_t> rgb(left.rgb.size());
  for (size_t p = 0; p < left.pixel_count(); ++p) {
    rgb[3 * p] = to_byte(luma(&left.rgb[3 * p]) / 255.0);
    rgb[3 * p + 1] = right.rgb[3 * p + 1];
    rgb[3 * p + 2] = right.rgb[3 * p + 2];
  }
  return rgb;
}

std::vector<BandDisagreement> lr_disagreement_by_latitude(const Frame& left, const Frame& right,
                                                          double band_degrees) {
  assert(left.width == right.width && left.height == right.height && band_degrees > 0);
  const int bands = int(std::ceil(180.0 / band_degrees - 1e-9));
  std::vector<BandDisagreement> out(static_cast<size_t>(bands));
  std::vector<double> mismatch(static_cast<size_t>(bands), 0.0),
      luma_sum(static_cast<size_t>(bands), 0.0);
  for (int b = 0; b < bands; ++b) {
    out[size_t(b)].lat_max_deg = 90.0 - b * band_degrees;
    out[size_t(b)].lat_min_deg = std::max(-90.0, 90.0 - (b + 1) * band_degrees);
  }
  for (int y = 0; y < left.height; ++y) {
    const double lat = 90.0 - 180.0 * (y + 0.5) / left.height;
    const int b = std::min(bands - 1, int((90.0 - lat) / band_degrees));
    for (int x = 0; x < left.width; ++x) {
      const size_t p = size_t(y) * size_t(left.width) + size_t(x);
      ++out[size_t(b)].pixels;
      mismatch[size_t(b)] += left.tri[p] != right.tri[p];
      luma_sum[size_t(b)] += std::fabs(luma(&left.rgb[3 * p]) - luma(&right.rgb[3 * p]));
    }
  }
  for (int b = 0; b < bands; ++b) {
    BandDisagreement& d = out[size_t(b)];
    if (d.pixels == 0) continue;
    d.triangle_mismatch = mismatch[size_t(b)] / double(d.pixels);
    d.mean_abs_luma = luma_sum[size_t(b)] / double(d.pixels);
  }
  return out;
}

SeamContinuity seam_continuity(const Frame& f) {
  assert(f.width >= 2);
  SeamContinuity s;
  const size_t w = size_t(f.width);
  auto pair = [&](size_t xa, size_t xb, double* mismatch, double* rgb) {
    double m = 0, d = 0;
    for (int y = 0; y < f.height; ++y) {
      const size_t a = size_t(y) * w + xa, b = size_t(y) * w + xb;
      m += f.tri[a] != f.tri[b];
      for (int k = 0; k < 3; ++k)
        d += std::fabs(double(f.rgb[3 * a + size_t(k)]) - double(f.rgb[3 * b + size_t(k)]));
    }
    *mismatch = m / f.height;
    *rgb = d / (3.0 * f.height);
  };
  pair(0, w - 1, &s.seam_triangle_mismatch, &s.seam_mean_abs_rgb);
  double msum = 0, dsum = 0;
  for (size_t x = 0; x + 1 < w; ++x) {
    double m, d;
    pair(x, x + 1, &m, &d);
    msum += m, dsum += d;
  }
  s.typical_triangle_mismatch = msum / double(w - 1);
  s.typical_mean_abs_rgb = dsum / double(w - 1);
  return s;
}

bool ods_disc_covered(const pvs::CellLayout& layout, const std::vector<uint32_t>& cells,
                      Vec3 centre, double radius) {
  for (int k = -1; k < 64; ++k) {  // k = -1: the centre
    const double a = 2 * pvs_runtime::kOdsPi * k / 64;
    const double p[3] = {centre.x + (k < 0 ? 0 : radius * std::cos(a)), centre.y,
                         centre.z + (k < 0 ? 0 : radius * std::sin(a))};
    bool in = false;
    for (uint32_t u : cells) {
      const pvs::Box r = layout.view_region(u);
      in = in || (p[0] >= r.min[0] && p[0] <= r.max[0] && p[1] >= r.min[1] && p[1] <= r.max[1] &&
                  p[2] >= r.min[2] && p[2] <= r.max[2]);
    }
    if (!in) return false;
  }
  return true;
}

}  // namespace vislib
