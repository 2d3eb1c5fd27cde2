// edge_lines.h: one line per run of collinear edges, so that the edges of a T-junction compute
// their coverage from the same two points (docs/visibility-math.md §2.5, "T-junctions").
//
// The static kernel decides which side of an edge a pixel ray passes from the edge's line alone
// (the triangle is the intersection of three wedges; where an edge ends is its neighbours'
// business). Two triangles sharing an edge compute bit-identical coefficients from the same two
// points, so their coverage meets without crack. Two triangles whose edges lie on one line but end
// at different points (a T-junction: a vertex of one on the edge of another, as map compilers and
// CSG leave everywhere) compute them from different points, and where the exact value is zero
// (the ray on that line over a stretch of the segment) rounding gives the two edges independent
// signs: the ray leaks through a crack of zero width over a stretch of positive length, and
// whatever lies behind is reported visible. Computing every edge of such a run from the run's two
// extreme points makes the coefficients bit-identical again.
//
// A run: edges joined, through shared endpoints (equal positions), with edges collinear with them
// (the cross product of their directions from the shared point is zero in double, with
// -ffp-contract=off: collinear points whose differences are exact, such as integer map
// coordinates, and some within rounding of a line). Collinear edges that touch nowhere are not
// joined; nor are moving triangles (the dynamic kernel).
//
// Build it once per scene and key state and pass it in SegmentOptions::edge_lines to every run (a
// bake does; `pvs segment` builds one for its run); without it the kernel builds one per call, so
// the results never depend on whether it was passed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct EdgeLines {
  static constexpr uint32_t kNone = UINT32_MAX;
  // Per edge 3 * triangle + e (edge e from corner e to corner (e+1) % 3), its run's line in
  // `lines`, or kNone; empty when no edge of the scene belongs to a run (4 bytes an edge).
  std::vector<uint32_t> edge_line;
  // One per run of two or more distinct edges: its two extreme points in lexicographic order
  // (lex_less), P < Q.
  std::vector<std::array<Vec3, 2>> lines;
  size_t state = 0;           // the key state whose positions it was built from
  size_t triangle_count = 0;  // of the scene it was built for
  const Scene* scene = nullptr;

  // True when it was built for `scene` in key state `state` (the kernel checks it and throws
  // std::invalid_argument otherwise).
  bool matches(const Scene& s, size_t st) const {
    return scene == &s && state == st && triangle_count == s.triangle_count();
  }
  // The line of edge e of triangle `tri` when it has one (P < Q), else false.
  bool line_of(uint32_t tri, int e, Vec3& P, Vec3& Q) const {
    if (edge_line.empty()) return false;
    const uint32_t l = edge_line[size_t(tri) * 3 + size_t(e)];
    if (l == kNone) return false;
    P = lines[l][0];
    Q = lines[l][1];
    return true;
  }
  // Number of edges that take a run's line.
  size_t edge_count() const;
};

// Memory while building, beyond the result (4 bytes an edge, 48 a run): 8 bytes a vertex, 8 a
// distinct point and 20 a run of edges, plus incident lists of at most kEdgeLinesIncidentBudget
// entries (4 bytes each), the points being taken in ranges that fit it (each range reads every
// edge once more). Deterministic; O(V log V + E * ranges + sum over points of (incident
// edges)^2, capped per point at kEdgeLinesPairCap incident edges, beyond which only edges
// adjacent in direction order are compared).
constexpr size_t kEdgeLinesPairCap = 64;
constexpr size_t kEdgeLinesIncidentBudget = size_t(16) << 20;  // 64 MB of incident lists
// `incident_budget` (>= 1; entries) sets the ranges' size: the result does not depend on it.
EdgeLines build_edge_lines(const Scene& scene, size_t state = 0,
                           size_t incident_budget = kEdgeLinesIncidentBudget);

}  // namespace vislib
