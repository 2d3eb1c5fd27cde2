// quake_bsp_volumes.cpp: leaf volumes of quake_bsp_volumes.h. Each face of a polytope is the
// half-space's plane as a large square, clipped by every other half-space (the "base winding"
// construction of the Quake map compilers).
#include "vislib/scene/quake_bsp_volumes.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace vislib {

namespace {

// Keeps the part of `poly` where dot(h.normal, p) <= h.offset.
std::vector<Vec3> clip(const std::vector<Vec3>& poly, const HalfSpace& h) {
  std::vector<Vec3> out;
  const size_t n = poly.size();
  if (n == 0) return out;
  std::vector<double> d(n);
  for (size_t i = 0; i < n; ++i) d[i] = dot(h.normal, poly[i]) - h.offset;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    if (d[i] <= 0) out.push_back(poly[i]);
    if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
      const double t = d[i] / (d[i] - d[j]);
      out.push_back(poly[i] + (poly[j] - poly[i]) * t);
    }
  }
  return out;
}

// A square on the plane of `h`, of half side `size` around the plane's point nearest the origin,
// counter-clockwise seen from outside (from +normal).
std::vector<Vec3> base_square(const HalfSpace& h, double size) {
  const Vec3 n = h.normal * (1.0 / length(h.normal));
  const Vec3 c = n * (h.offset / length(h.normal));
  Vec3 a = std::fabs(n.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 u = cross(a, n);
  u = u * (1.0 / length(u));
  const Vec3 v = cross(n, u);
  return {c + (-u - v) * size, c + (u - v) * size, c + (u + v) * size, c + (-u + v) * size};
}

ConvexPolytope make_polytope(const std::vector<HalfSpace>& hs, double size) {
  ConvexPolytope p;
  p.halfspaces = hs;
  for (size_t i = 0; i < hs.size(); ++i) {
    std::vector<Vec3> poly = base_square(hs[i], size);
    for (size_t j = 0; j < hs.size() && poly.size() >= 3; ++j)
      if (j != i) poly = clip(poly, hs[j]);
    if (poly.size() >= 3) p.faces.push_back(std::move(poly));
  }
  if (p.volume() <= 0) p.faces.clear();
  return p;
}

}  // namespace

double ConvexPolytope::volume() const {
  double v = 0;
  for (const auto& f : faces)
    for (size_t k = 1; k + 1 < f.size(); ++k) v += dot(f[0], cross(f[k], f[k + 1]));
  return v / 6;
}

Box3 ConvexPolytope::bounds() const {
  Box3 b;
  for (const auto& f : faces)
    for (const Vec3& p : f) b.extend(p);
  return b;
}

ConvexPolytope inset_polytope(const ConvexPolytope& p, double distance) {
  // Large enough to reach across the polytope from any of its planes: from its corners, or (no
  // faces yet) from the planes' distances to the origin, which bound a box-clipped polytope's.
  double size = 1;
  if (!p.empty()) {
    const Box3 b = p.bounds();
    size += 4 * (length(b.max - b.min) + length(b.min) + length(b.max));
  } else {
    for (const HalfSpace& h : p.halfspaces) size += 4 * std::fabs(h.offset) / length(h.normal);
  }
  std::vector<HalfSpace> hs = p.halfspaces;
  for (HalfSpace& h : hs) h.offset -= distance * length(h.normal);
  return make_polytope(hs, size);
}

BspViewRegion bsp_leaf_view_region(const ConvexPolytope& leaf_volume, double near) {
  assert(near > 0);
  const double clearance = kNearClearanceFactor * near;
  const double smallest = std::max(kBspLeafMinInset, clearance);
  for (double d = std::max(kBspLeafInset, clearance); d >= smallest; d /= 2) {
    ConvexPolytope v = inset_polytope(leaf_volume, d);
    if (!v.empty()) return {std::move(v), d};
  }
  if (ConvexPolytope v = inset_polytope(leaf_volume, clearance); !v.empty())
    return {std::move(v), clearance};
  // Thinner than twice the clearance: the largest inset that leaves a volume, by bisection
  // (emptiness grows with the inset), then half of it.
  constexpr int kBisections = 64;
  double lo = 0, hi = clearance;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (inset_polytope(leaf_volume, mid).empty() ? hi : lo) = mid;
  }
  const double d = 0.5 * lo;
  if (d > 0)
    if (ConvexPolytope v = inset_polytope(leaf_volume, d); !v.empty())
      return {std::move(v), d, d / kNearClearanceFactor};
  return {leaf_volume, 0};
}

std::vector<BspLeafPiece> bsp_leaf_pieces(const QuakeBsp& bsp) {
  const BspModel& world = bsp.models[0];
  const Vec3 lo{world.mins[0], world.mins[1], world.mins[2]};
  const Vec3 hi{world.maxs[0], world.maxs[1], world.maxs[2]};
  // Large enough to reach across the box from any plane through it.
  const double size = 4 * (length(hi - lo) + length(lo) + length(hi)) + 1;
  std::vector<HalfSpace> path = {{{1, 0, 0}, hi.x},   {{-1, 0, 0}, -lo.x}, {{0, 1, 0}, hi.y},
                                 {{0, -1, 0}, -lo.y}, {{0, 0, 1}, hi.z},   {{0, 0, -1}, -lo.z}};
  std::vector<BspLeafPiece> out;
  // Depth-first, front child first; the stack holds (child reference, path length to restore).
  struct Item {
    int32_t child;
    size_t depth;
    HalfSpace h;
  };
  std::vector<Item> stack;
  const int32_t head = world.headnode[0];
  stack.push_back({head, path.size(), {}});
  bool root = true;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    path.resize(it.depth);
    if (!root) path.push_back(it.h);
    root = false;
    if (it.child < 0) {
      out.push_back({uint32_t(-(int64_t(it.child) + 1)), make_polytope(path, size)});
      continue;
    }
    const BspNode& node = bsp.nodes[size_t(it.child)];
    const BspPlane& pl = bsp.planes[node.plane];
    const Vec3 n{pl.normal[0], pl.normal[1], pl.normal[2]};
    const double d = pl.dist;
    // Back first on the stack so that the front child is taken first.
    stack.push_back({node.children[1], path.size(), {n, d}});          // dot(n, p) <= d
    stack.push_back({node.children[0], path.size(), {n * -1.0, -d}});  // dot(n, p) >= d
  }
  return out;
}

}  // namespace vislib
