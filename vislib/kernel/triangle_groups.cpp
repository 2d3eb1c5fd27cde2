// triangle_groups.cpp: see triangle_groups.h.
#include "vislib/kernel/triangle_groups.h"

#include <algorithm>
#include <cmath>

namespace vislib {

int group_corners(const Scene& scene, size_t state, uint32_t first, uint32_t end, Vec3* out) {
  const auto c = scene.corners(first, state);
  out[0] = c[0];
  out[1] = c[1];
  out[2] = c[2];
  int n = 3;
  for (uint32_t t = first + 1; t < end; ++t)
    out[n++] = scene.positions[state][scene.triangles[t][2]];
  return n;
}

namespace {

// True when triangle t + 1 continues the fan of triangle t: (a, b, c) then (a, c, d), one object.
bool continues_fan(const Scene& scene, uint32_t t) {
  const auto& p = scene.triangles[t];
  const auto& q = scene.triangles[t + 1];
  return scene.triangle_object[t] == scene.triangle_object[t + 1] && q[0] == p[0] && q[1] == p[2] &&
         q[2] != p[0] && q[2] != p[1] && q[2] != p[2];
}

// True when the polygon c[0 .. n) is convex and planar as triangle_groups.h requires: no corner
// turns against the first triangle's normal, each fan triangle (c0, ci, ci+1) turns with it
// (strictly: none is degenerate), a corner that does not turn has its two edges exactly
// collinear (the cross product of its edge directions is zero in double, as build_edge_lines
// tests it, so that both edges take their run's line), and every corner lies within
// kGroupPlaneTolerance of the first triangle's plane.
bool convex_planar(const Vec3* c, int n) {
  const Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
  const double nl = length(normal);
  if (!(nl > 0) || !(nl < INFINITY)) return false;
  double extent = 0;
  for (int i = 1; i < n; ++i)
    for (int a = 0; a < 3; ++a) extent = std::max(extent, std::fabs(c[i][a] - c[0][a]));
  for (int i = 3; i < n; ++i)
    if (!(std::fabs(dot(normal, c[i] - c[0])) <= kGroupPlaneTolerance * extent * nl)) return false;
  for (int i = 1; i + 1 < n; ++i)
    if (!(dot(cross(c[i] - c[0], c[i + 1] - c[0]), normal) > 0)) return false;
  for (int i = 0; i < n; ++i) {
    const Vec3 &a = c[(i + n - 1) % n], &b = c[i], &d = c[(i + 1) % n];
    const double turn = dot(cross(b - a, d - b), normal);
    if (turn > 0) continue;
    if (!(turn == 0) || !(cross(a - b, d - b) == Vec3{0, 0, 0})) return false;
  }
  return true;
}

}  // namespace

TriangleGroups build_triangle_groups(const Scene& scene, size_t state) {
  TriangleGroups g;
  const size_t n = scene.triangle_count();
  if (n == 0 || scene.is_dynamic() || scene.sphere_count() > 0) return g;
  g.first.reserve(n + 1);
  Vec3 c[kMaxGroupCorners];
  uint32_t t = 0;
  bool any = false;
  while (t < n) {
    g.first.push_back(t);
    uint32_t end = t + 1;
    if (!scene.triangle_see_through(t)) {
      // Grow while the next triangle continues the fan and the polygon stays convex and planar.
      while (end < n && int(end - t) + 3 <= kMaxGroupCorners && continues_fan(scene, end - 1)) {
        const int k = group_corners(scene, state, t, end + 1, c);
        if (!convex_planar(c, k)) break;
        ++end;
      }
    }
    any |= end - t > 1;
    t = end;
  }
  if (!any) return TriangleGroups{};
  g.first.push_back(uint32_t(n));
  return g;
}

}  // namespace vislib
