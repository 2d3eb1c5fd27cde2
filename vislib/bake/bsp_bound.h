// bsp_bound.h: conservative bounds of what a Quake map's portal runs can see, so that each run
// composites only the triangles that can be visible from it.
//
// A triangle that no eye of a segment sees changes no first hit from it: restricting a run's
// scene, occluders included, to any superset of what the segment sees leaves the run's visible
// set unchanged (the kernel walks a tree over the superset only, triangle_bvh.h). The bound of a
// run is a set of leaves and the triangles that touch them:
//  - Portal flow (BspBound::Portals): a ray from a portal point that goes on through the leaf
//    beyond crosses portals p = q0, q1, q2, ... in order, each qj at a point in front of q0's
//    plane (the ray moves away from it) while q0's crossing lies behind qj's plane. So qj has a
//    vertex in front of q0's plane and q0 a vertex behind qj's (the compiler's base vis, within
//    kBspBoundDistance); the leaves a flood from p's far leaf reaches through such portals hold
//    every leaf the ray passes through, and the hit lies on a triangle touching the last one.
//  - The map's own visibility (BspBound::MapVis): the leaves the map's vis data says each of the
//    portal's two leaves sees, and the two leaves. Exact only where the compiler's vis is
//    conservative; a user who trusts it asks for it.
// A triangle touches a leaf when the tree walk of its corners reaches the leaf with planes widened
// by kBspBoundDistance (a triangle on a node's plane reaches both sides), so models other than the
// world's, liquid surfaces and the coincident faces of sky and liquid boundaries all count.
// docs/quake.md "Restriction" measures what it buys.
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/bake/bsp_portals.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene.h"

namespace vislib {

enum class BspBound { None, Portals, MapVis };

// Points within this distance of a plane (Quake units) count on both of its sides, for the portal
// flow's front and back tests and for the leaves a triangle touches: the map's float planes and
// vertices agree to about 1e-3 units (kBspOnFaceDistance), a pixel ray within kSideTolerance of a
// portal's plane drifts from it by under 1e-5 units over a map, and a wider margin only adds
// leaves.
constexpr double kBspBoundDistance = 0.1;

// For each leaf of the map (leaf number), the triangles of `scene` (key state 0; the map imported
// as quake_bsp.h says) that touch it, increasing. Deterministic.
std::vector<std::vector<uint32_t>> bsp_leaf_triangles(const QuakeBsp& bsp, const Scene& scene);

// For each portal of `portals` (bsp_leaf_portals, Quake coordinates) the leaves its runs can see,
// increasing: with Portals the leaves of the flood through each of its two directions (its two
// leaves included), with MapVis its two leaves and the leaves each of them sees
// (bsp_leaf_sees). Deterministic; Portals costs O(portals x portals reached x vertices).
std::vector<std::vector<uint32_t>> bsp_portal_bound_leaves(const QuakeBsp& bsp,
                                                           const std::vector<BspPortal>& portals,
                                                           BspBound bound);

// The triangles of bound `leaves` (increasing leaf numbers): the union of leaf_triangles over them,
// increasing.
std::vector<uint32_t> bound_triangles(const std::vector<std::vector<uint32_t>>& leaf_triangles,
                                      const std::vector<uint32_t>& leaves);

}  // namespace vislib
