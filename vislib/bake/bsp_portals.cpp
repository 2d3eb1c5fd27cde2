// bsp_portals.cpp: portals between BSP leaf volumes, and the triangles on or in a volume
// (bsp_portals.h).
#include "vislib/bake/bsp_portals.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "vislib/scene/quake_bsp.h"

namespace vislib {

namespace {

// Two faces of leaf volumes face each other when their unit normals are opposite to within this
// (1 + dot of the normals; the volumes come from the same float planes).
constexpr double kBspFaceOppositeNormals = 1e-9;

// A face of a leaf volume with its plane: unit outward normal and offset (dot(n, p) = offset).
struct PlanarFace {
  const std::vector<Vec3>* poly;
  Vec3 normal;
  double offset;
};

double polygon_area(const std::vector<Vec3>& poly) {
  Vec3 n{0, 0, 0};
  for (size_t i = 0; i < poly.size(); ++i) n = n + cross(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * length(n);
}

// The part of convex polygon `a` inside convex polygon `b` (both on one plane; `b`
// counter-clockwise seen from `nb`): `a` clipped by the inward half-plane of each edge of `b`.
std::vector<Vec3> clip_to(std::vector<Vec3> a, const std::vector<Vec3>& b, Vec3 nb) {
  for (size_t i = 0; i < b.size() && a.size() >= 3; ++i) {
    const Vec3 p = b[i], inward = cross(nb, b[(i + 1) % b.size()] - p);
    std::vector<Vec3> out;
    for (size_t k = 0; k < a.size(); ++k) {
      const Vec3 u = a[k], v = a[(k + 1) % a.size()];
      const double su = dot(inward, u - p), sv = dot(inward, v - p);
      if (su >= 0) out.push_back(u);
      if ((su > 0 && sv < 0) || (su < 0 && sv > 0)) out.push_back(u + (v - u) * (su / (su - sv)));
    }
    a = std::move(out);
  }
  if (a.size() < 3) a.clear();
  return a;
}

// The overlap of a face of `a` and a face of `b` on one plane facing each other, as a portal
// polygon of the face of `a` (empty when none has kBspPortalMinArea).
std::vector<Vec3> shared_face(const std::vector<PlanarFace>& a, const std::vector<PlanarFace>& b) {
  for (const PlanarFace& fa : a)
    for (const PlanarFace& fb : b) {
      if (1.0 + dot(fa.normal, fb.normal) > kBspFaceOppositeNormals) continue;
      bool coplanar = true;
      for (const Vec3& v : *fb.poly)
        coplanar = coplanar && std::fabs(dot(fa.normal, v) - fa.offset) <= kBspPlaneDistance;
      if (!coplanar) continue;
      std::vector<Vec3> overlap = clip_to(*fa.poly, *fb.poly, fb.normal);
      if (!overlap.empty() && polygon_area(overlap) >= kBspPortalMinArea) return overlap;
    }
  return {};
}

bool boxes_touch(const Box3& a, const Box3& b) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] > b.max[k] + kBspPlaneDistance || b.min[k] > a.max[k] + kBspPlaneDistance)
      return false;
  return true;
}

}  // namespace

Vec3 polygon_normal(const std::vector<Vec3>& poly) {
  Vec3 n{0, 0, 0};
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n * (1.0 / length(n));
}

std::vector<BspPortal> bsp_leaf_portals(const std::vector<BspLeafPiece>& pieces,
                                        const std::vector<uint32_t>& leaves) {
  assert(std::is_sorted(leaves.begin(), leaves.end()));
  const size_t L = leaves.size();
  std::vector<std::vector<PlanarFace>> faces(L);
  std::vector<Box3> bounds(L);
  for (const BspLeafPiece& piece : pieces) {
    const auto it = std::lower_bound(leaves.begin(), leaves.end(), piece.leaf);
    if (it == leaves.end() || *it != piece.leaf || piece.volume.empty()) continue;
    const size_t i = size_t(it - leaves.begin());
    for (const auto& f : piece.volume.faces) {
      const Vec3 n = polygon_normal(f);
      faces[i].push_back({&f, n, dot(n, f[0])});
    }
    const Box3 b = piece.volume.bounds();
    bounds[i].extend(b.min);
    bounds[i].extend(b.max);
  }
  std::vector<BspPortal> out;
  for (size_t a = 0; a < L; ++a)
    for (size_t b = a + 1; b < L; ++b) {
      if (bounds[a].empty() || bounds[b].empty() || !boxes_touch(bounds[a], bounds[b])) continue;
      std::vector<Vec3> poly = shared_face(faces[a], faces[b]);
      if (poly.empty()) continue;
      BspPortal p;
      p.leaves[0] = leaves[a];
      p.leaves[1] = leaves[b];
      p.normal = polygon_normal(poly);
      p.area = polygon_area(poly);
      p.polygon = std::move(poly);
      out.push_back(std::move(p));
    }
  return out;
}

namespace {

// `poly` clipped to the half-space dot(n, x) <= offset (closed).
std::vector<Vec3> clip_polygon(const std::vector<Vec3>& poly, Vec3 n, double offset) {
  std::vector<Vec3> out;
  for (size_t k = 0; k < poly.size(); ++k) {
    const Vec3 u = poly[k], v = poly[(k + 1) % poly.size()];
    const double su = dot(n, u) - offset, sv = dot(n, v) - offset;
    if (su <= 0) out.push_back(u);
    if ((su < 0 && sv > 0) || (su > 0 && sv < 0)) out.push_back(u + (v - u) * (su / (su - sv)));
  }
  if (out.size() < 3) out.clear();
  return out;
}

Vec3 vertex_mean(const std::vector<Vec3>& poly) {
  Vec3 c{0, 0, 0};
  for (const Vec3& v : poly) c = c + v;
  return c * (1.0 / double(poly.size()));
}

// The part of `tri` inside `volume`'s half-spaces moved inward by kBspOwnMinWidth, leaving out
// half-space `skip` (a face the triangle lies on); empty when it has no area.
std::vector<Vec3> part_inside(std::vector<Vec3> tri, const ConvexPolytope& volume, size_t skip) {
  for (size_t h = 0; h < volume.halfspaces.size() && !tri.empty(); ++h) {
    if (h == skip) continue;
    const HalfSpace& hs = volume.halfspaces[h];
    tri = clip_polygon(tri, hs.normal, hs.offset - kBspOwnMinWidth * length(hs.normal));
  }
  return polygon_area(tri) > 0 ? tri : std::vector<Vec3>{};
}

}  // namespace

std::vector<VolumeTriangle> bsp_volume_triangles(const Scene& scene, const ConvexPolytope& volume,
                                                 size_t state) {
  std::vector<VolumeTriangle> out;
  if (volume.empty()) return out;
  Box3 box = volume.bounds();
  for (int k = 0; k < 3; ++k) {
    box.min[k] -= kBspOnFaceDistance;
    box.max[k] += kBspOnFaceDistance;
  }
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    const auto c = scene.corners(t, state);
    bool outside = false;
    for (int k = 0; k < 3 && !outside; ++k)
      outside = std::max({c[0][k], c[1][k], c[2][k]}) < box.min[k] ||
                std::min({c[0][k], c[1][k], c[2][k]}) > box.max[k];
    if (outside) continue;
    const std::vector<Vec3> tri = {c[0], c[1], c[2]};
    // Inside: through the interior. On a face: every corner on the face's plane, inside the
    // face's other planes.
    std::vector<Vec3> part = part_inside(tri, volume, volume.halfspaces.size());
    for (size_t h = 0; h < volume.halfspaces.size() && part.empty(); ++h) {
      const HalfSpace& hs = volume.halfspaces[h];
      const double len = length(hs.normal);
      bool on = len > 0;
      for (const Vec3& v : tri)
        on = on && std::fabs(dot(hs.normal, v) - hs.offset) <= kBspOnFaceDistance * len;
      if (on) part = part_inside(tri, volume, h);
    }
    if (!part.empty()) out.push_back({t, vertex_mean(part)});
  }
  return out;
}

std::vector<Vec3> bsp_portal_clear_part(const BspPortal& portal, const ConvexPolytope& a,
                                        const ConvexPolytope& b, double clearance) {
  std::vector<Vec3> part = portal.polygon;
  const double offset = dot(portal.normal, portal.polygon[0]);
  for (const ConvexPolytope* v : {&a, &b})
    for (const HalfSpace& h : v->halfspaces) {
      const double len = length(h.normal);
      if (!(len > 0) || part.empty()) continue;
      // The portal's own plane (either orientation) bounds neither side's clearance.
      const double s = dot(h.normal, portal.normal) / len;
      if (1.0 - std::fabs(s) < 1e-9 && std::fabs(h.offset / len - s * offset) <= kBspPlaneDistance)
        continue;
      part = clip_polygon(part, h.normal, h.offset - clearance * len);
    }
  return polygon_area(part) > 0 ? part : std::vector<Vec3>{};
}

BspPortalCover bsp_portal_cover(const BspPortal& portal, const Scene& scene) {
  const double offset = dot(portal.normal, portal.polygon[0]);
  Box3 box;
  for (const Vec3& v : portal.polygon) box.extend(v);
  // The portal's outward edge normals (unit, in its plane): it is counter-clockwise seen from its
  // normal's side.
  const size_t n = portal.polygon.size();
  std::vector<Vec3> outward(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 o = cross(portal.polygon[(i + 1) % n] - portal.polygon[i], portal.normal);
    outward[i] = length(o) > 0 ? o * (1.0 / length(o)) : Vec3{0, 0, 0};
  }
  // The polygon clipped by the portal's edges moved inward by `band` (>= 0); a repeated corner
  // (an edge of no length) bounds nothing.
  auto inside = [&](std::vector<Vec3> poly, double band) {
    for (size_t i = 0; i < n && !poly.empty(); ++i)
      if (outward[i] != Vec3{0, 0, 0})
        poly = clip_polygon(poly, outward[i], dot(outward[i], portal.polygon[i]) - band);
    return poly;
  };
  // The portal with its edges moved inward by the band: the parts are the triangles clipped to it.
  const std::vector<Vec3> inner = inside(portal.polygon, kBspOwnMinWidth);
  BspPortalCover cover;
  if (inner.empty()) {  // narrower than twice the band: all of it lies in the band
    cover.closed = true;
    return cover;
  }
  double covered = 0;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    if (scene.triangle_see_through(t)) continue;
    const auto c = scene.corners(t);
    bool apart = false;
    for (int k = 0; k < 3 && !apart; ++k) {
      double lo = INFINITY, hi = -INFINITY;
      for (const Vec3& s : c) {
        lo = std::min(lo, scene_to_quake(s)[k]);
        hi = std::max(hi, scene_to_quake(s)[k]);
      }
      apart = lo > box.max[k] + kBspOnFaceDistance || hi < box.min[k] - kBspOnFaceDistance;
    }
    if (apart) continue;
    std::vector<Vec3> tri;
    bool on = true;
    for (const Vec3& s : c) {
      const Vec3 q = scene_to_quake(s);
      on = on && std::fabs(dot(portal.normal, q) - offset) <= kBspOnFaceDistance;
      tri.push_back(q);
    }
    if (!on) continue;
    tri = inside(std::move(tri), kBspOwnMinWidth);
    if (tri.empty() || !(polygon_area(tri) > 0)) continue;
    covered += polygon_area(tri);
    cover.parts.push_back(std::move(tri));
  }
  // The triangles of a map's face share its corners exactly and do not overlap, so their areas
  // add up to the inner part's to within rounding.
  cover.closed = covered >= polygon_area(inner) * (1 - 1e-9);
  return cover;
}

std::vector<Segment> bsp_portal_open_pieces(const Segment& s, const BspPortal& portal,
                                            const BspPortalCover& cover, double clearance,
                                            double min_length) {
  if (cover.parts.empty()) return {s};
  // Each part's interval of s, the part grown by `clearance` (each edge moved outward by it: a
  // superset of the points within clearance of it).
  std::vector<std::pair<double, double>> shut;
  const Vec3 d = s.to - s.from;
  for (const std::vector<Vec3>& part : cover.parts) {
    Vec3 centre{0, 0, 0};
    for (const Vec3& v : part) centre = centre + v;
    centre = centre * (1.0 / double(part.size()));
    double lo = 0, hi = 1;
    for (size_t i = 0; i < part.size() && lo <= hi; ++i) {
      Vec3 o = cross(part[(i + 1) % part.size()] - part[i], portal.normal);
      const double len = length(o);
      if (!(len > 0)) continue;
      o = o * (1.0 / len);
      if (dot(o, centre - part[i]) > 0) o = o * -1.0;  // the part's winding is either way
      // dot(o, from + t d - part[i]) <= clearance
      const double a = dot(o, d), b = clearance - dot(o, s.from - part[i]);
      if (a > 0)
        hi = std::min(hi, b / a);
      else if (a < 0)
        lo = std::max(lo, b / a);
      else if (b < 0)
        hi = -1;  // parallel and outside
    }
    if (lo <= hi) shut.push_back({lo, hi});
  }
  std::sort(shut.begin(), shut.end());
  std::vector<Segment> out;
  double open = 0;
  auto piece = [&](double t0, double t1) {
    Segment p = s;
    p.from = s.from + d * t0;
    p.to = s.from + d * t1;
    if (length(p.to - p.from) > min_length) out.push_back(p);
  };
  for (const auto& [lo, hi] : shut) {
    if (lo > open) piece(open, lo);
    open = std::max(open, hi);
  }
  if (open < 1) piece(open, 1);
  return out;
}

ConvexPolytope polytope_to_scene(const ConvexPolytope& p) {
  ConvexPolytope s;
  for (const HalfSpace& h : p.halfspaces)
    s.halfspaces.push_back({quake_to_scene(h.normal), h.offset});
  for (const std::vector<Vec3>& f : p.faces) {
    s.faces.emplace_back();
    for (const Vec3& v : f) s.faces.back().push_back(quake_to_scene(v));
  }
  return s;
}

}  // namespace vislib
