// ray_triangle.h: the one ray-triangle intersection of vislib's own code (Möller-Trumbore in
// double); Embree's traversal is in eval/embree_scene.h.
#pragma once

#include <array>
#include <cmath>
#include <optional>

#include "vislib/base/vec.h"

namespace vislib {

// The parameter t of the point o + t d where the line through `o` along `d` crosses the triangle
// `c` (edges included: barycentric u, v >= 0 and u + v <= 1), or nullopt when it misses, runs
// parallel to the triangle's plane, or the triangle is degenerate (a zero or non-finite
// determinant). t may be zero or negative (behind `o`): callers keep the range they need.
inline std::optional<double> ray_triangle(Vec3 o, Vec3 d, const std::array<Vec3, 3>& c) {
  const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
  const Vec3 pv = cross(d, e2);
  const double det = dot(e1, pv);
  if (det == 0 || !std::isfinite(det)) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 tv = o - c[0];
  const double u = dot(tv, pv) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3 qv = cross(tv, e1);
  const double v = dot(d, qv) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  return dot(e2, qv) * inv;
}

}  // namespace vislib
