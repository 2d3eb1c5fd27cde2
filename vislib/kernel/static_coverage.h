// static_coverage.h: the coverage step of the from-segment kernel for one static triangle and one
// pixel (docs/visibility-math.md §2: triple products with canonically oriented edges, the §2.5 tie
// rule). Used by the static kernel (segment_visibility.cpp), by the dynamic kernel for triangles
// that do not move (dynamic_visibility.cpp), and tested directly on hard cases.
#pragma once

#include "vislib/base/vec.h"
#include "vislib/kernel/edge_lines.h"
#include "vislib/kernel/interval_list.h"
#include "vislib/kernel/triangle_groups.h"

namespace vislib {

// Per-triangle quantities of §2 for one segment, re-centred at v0; or those of a group's convex
// polygon (triangle_groups.h, §2.6): its boundary edges, and the plane of its first triangle.
struct StaticTriangle {
  int edges = 3;                                    // 3 for a triangle, up to kMaxGroupCorners
  Vec3 KA[kMaxGroupCorners], KB[kMaxGroupCorners];  // per edge c[i] -> c[i+1]: (Q-P) x Delta and
                                                    // (Q-P) x (v0-P), canonical P<Q (P, Q: the
                                                    // edge's ends, or its run's line: edge_lines.h)
  double rho[kMaxGroupCorners];                     // +1 if the polygon runs P->Q, else -1
  Vec3 n;                                           // (b-a) x (c-a) of the first three corners
  double N0, N1;                                    // n.(a-v0), n.Delta
};
// With `lines`, an edge of triangle `tri` that belongs to a run of collinear edges takes its
// KA, KB from the run's line (edge_lines.h); its rho stays the triangle's own.
StaticTriangle prepare_static_triangle(const Vec3 corners[3], Vec3 v0, Vec3 v1,
                                       const EdgeLines* lines = nullptr, uint32_t tri = 0);

// An edge of the scene: edge e (corner e to corner (e + 1) % 3) of triangle tri.
struct EdgeRef {
  uint32_t tri = 0;
  int e = 0;
};
// The convex polygon corners[0 .. count) (count <= kMaxGroupCorners, a fan's corners in order,
// triangle_groups.h): edge i runs from corner i to corner (i + 1) % count and is edge refs[i] of
// the scene, whose run's line it takes with `lines` (as prepare_static_triangle does).
StaticTriangle prepare_static_polygon(const Vec3* corners, int count, Vec3 v0, Vec3 v1,
                                      const EdgeLines* lines, const EdgeRef* refs);

// The coefficients of one edge from corner a to corner b (world) for a segment from v0 with
// Delta = v1 - v0, as prepare_static_triangle computes them (§2.5): KA, KB and rho.
void static_edge(Vec3 a, Vec3 b, Vec3 v0, Vec3 delta, const EdgeLines* lines, EdgeRef ref, Vec3& KA,
                 Vec3& KB, double& rho);

// Coverage interval [lo, hi) and depth of a prepared triangle at pixel direction d (world,
// un-normalised) with face axes S, T used by the tie rule. False when empty.
bool static_coverage(const StaticTriangle& tri, Vec3 d, Vec3 S, Vec3 T, double near, double& lo,
                     double& hi, LinearDepth& depth);

}  // namespace vislib
