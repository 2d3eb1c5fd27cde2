// static_coverage.h: the coverage step of the from-segment kernel for one static triangle and one
// pixel (docs/visibility-math.md §2: triple products with canonically oriented edges, the §2.5 tie
// rule). Used by the static kernel (segment_visibility.cpp), by the dynamic kernel for triangles
// that do not move (dynamic_visibility.cpp), and tested directly on hard cases.
#pragma once

#include "vislib/base/vec.h"
#include "vislib/kernel/edge_lines.h"
#include "vislib/kernel/interval_list.h"

namespace vislib {

// Per-triangle quantities of §2 for one segment, re-centred at v0.
struct StaticTriangle {
  Vec3 KA[3], KB[3];  // per edge ab, bc, ca: (Q-P) x Delta and (Q-P) x (v0-P), canonical P<Q
                      // (P, Q: the edge's ends, or its run's line: edge_lines.h)
  double rho[3];      // +1 if the triangle runs P->Q, else -1
  Vec3 n;             // (b-a) x (c-a)
  double N0, N1;      // n.(a-v0), n.Delta
};
// With `lines`, an edge of triangle `tri` that belongs to a run of collinear edges takes its
// KA, KB from the run's line (edge_lines.h); its rho stays the triangle's own.
StaticTriangle prepare_static_triangle(const Vec3 corners[3], Vec3 v0, Vec3 v1,
                                       const EdgeLines* lines = nullptr, uint32_t tri = 0);

// Coverage interval [lo, hi) and depth of a prepared triangle at pixel direction d (world,
// un-normalised) with face axes S, T used by the tie rule. False when empty.
bool static_coverage(const StaticTriangle& tri, Vec3 d, Vec3 S, Vec3 T, double near, double& lo,
                     double& hi, LinearDepth& depth);

}  // namespace vislib
