// bsp_portals.cpp: portals between BSP leaf volumes and the base vis flood over them
// (bsp_portals.h; the flood follows ericw-tools vis, BasePortalVis and SimpleFlood).
#include "vislib/bake/bsp_portals.h"

#include <tbb/parallel_for.h>

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

// One direction of a portal: from leaf `from` into leaf `to` (indices into the leaf list), its
// plane's normal pointing into `to`.
struct DirectedPortal {
  uint32_t from = 0, to = 0;
  const std::vector<Vec3>* winding = nullptr;
  Vec3 normal;
  double offset = 0;
  Vec3 centre;  // of the winding's bounding sphere
  double radius = 0;
};

// Some vertex of `w` lies more than kBspPlaneDistance in front of (normal, offset).
bool any_in_front(const DirectedPortal& w, Vec3 normal, double offset) {
  if (dot(normal, w.centre) - offset + w.radius <= kBspPlaneDistance) return false;
  for (const Vec3& v : *w.winding)
    if (dot(normal, v) - offset > kBspPlaneDistance) return true;
  return false;
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
      p.offset = dot(p.normal, poly[0]);
      p.area = polygon_area(poly);
      for (const Vec3& v : poly) p.scene.push_back(quake_to_scene(v));
      p.quake = std::move(poly);
      out.push_back(std::move(p));
    }
  return out;
}

std::vector<std::vector<uint32_t>> bsp_portal_base_vis(const std::vector<BspPortal>& portals,
                                                       const std::vector<uint32_t>& leaves) {
  assert(std::is_sorted(leaves.begin(), leaves.end()));
  const size_t L = leaves.size();
  auto index_of = [&](uint32_t leaf) {
    const auto it = std::lower_bound(leaves.begin(), leaves.end(), leaf);
    assert(it != leaves.end() && *it == leaf);
    return uint32_t(it - leaves.begin());
  };
  // Portal i gives directed portals 2i (leaves[0] into leaves[1]) and 2i + 1 (back).
  std::vector<DirectedPortal> dir(2 * portals.size());
  std::vector<std::vector<uint32_t>> leaving(L);  // directed portals by the leaf they leave
  for (size_t i = 0; i < portals.size(); ++i) {
    const BspPortal& p = portals[i];
    Box3 box;
    for (const Vec3& v : p.quake) box.extend(v);
    const Vec3 centre = (box.min + box.max) * 0.5;
    double radius = 0;
    for (const Vec3& v : p.quake) radius = std::max(radius, length(v - centre));
    const uint32_t a = index_of(p.leaves[0]), b = index_of(p.leaves[1]);
    dir[2 * i] = {a, b, &p.quake, p.normal, p.offset, centre, radius};
    dir[2 * i + 1] = {b, a, &p.quake, p.normal * -1.0, -p.offset, centre, radius};
    leaving[a].push_back(uint32_t(2 * i));
    leaving[b].push_back(uint32_t(2 * i + 1));
  }
  std::vector<std::vector<uint32_t>> out(L);
  tbb::parallel_for(size_t(0), L, [&](size_t l) {
    std::vector<uint8_t> seen(L, 0), might(dir.size(), 0);
    std::vector<uint32_t> stack;
    seen[l] = 1;
    for (uint32_t src : leaving[l]) {
      const DirectedPortal& p = dir[src];
      // BasePortalVis: the portals a chain starting through p may cross next.
      for (size_t q = 0; q < dir.size(); ++q) {
        const DirectedPortal& d = dir[q];
        might[q] = q != src && any_in_front(d, p.normal, p.offset) &&
                   any_in_front(p, d.normal * -1.0, -d.offset);
      }
      // SimpleFlood from p's leaf through those portals.
      std::vector<uint8_t> flooded(L, 0);
      flooded[p.to] = 1;
      seen[p.to] = 1;
      stack.assign(1, p.to);
      while (!stack.empty()) {
        const uint32_t x = stack.back();
        stack.pop_back();
        for (uint32_t q : leaving[x])
          if (might[q] && !flooded[dir[q].to]) {
            flooded[dir[q].to] = 1;
            seen[dir[q].to] = 1;
            stack.push_back(dir[q].to);
          }
      }
    }
    for (size_t k = 0; k < L; ++k)
      if (seen[k]) out[l].push_back(leaves[k]);
  });
  return out;
}

}  // namespace vislib
