// bsp_portals.h: the portals between a Quake map's BSP leaves and the leaves a leaf may see through
// them (a conservative bound of its visible set, computed from the portals alone).
//
// The map file holds no portals (the compiler keeps them in a separate .prt file), so they are
// found from the leaf volumes (quake_bsp_volumes.h): two leaves are neighbours when a face of one
// and a face of the other lie on one plane with opposite normals and overlap with positive area
// (at least kBspPortalMinArea square units); the overlap is their portal, the part of a node's
// plane where the two leaves meet, as the compiler would write it.
//
// The bound (bsp_portal_base_vis) is the base vis of the map compilers' `vis` stage (ericw-tools
// vis: BasePortalVis, then SimpleFlood per portal): what a leaf sees beyond itself, a ray from
// inside it meets through a chain of portals, each crossed in its direction, and every portal of
// the chain after the first has some point strictly in front of the first's plane (the ray is
// there after crossing it) while the first has some point strictly behind the later one's plane.
// Every leaf reached by such chains from one of a leaf's portals may be visible; no other is,
// provided that the leaves not given (solid and sky leaves) are closed off by faces of the scene,
// so that no first hit lies beyond them (docs/quake.md, "Restricting a leaf's runs").
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {

// Two leaf volumes are neighbours when their shared face has at least this area (square Quake
// units; a real portal is at least about 1).
constexpr double kBspPortalMinArea = 1e-3;
// Points within this distance of a plane (Quake units) lie on it: the faces of neighbouring leaf
// volumes come from the same float planes and agree to about 1e-12 units. Used for the faces two
// volumes share and, in the flow, for "strictly in front of a portal's plane", where it errs
// towards dropping a portal only for portals that touch the plane within it (a ray that crossed
// the first portal is strictly in front of its plane).
constexpr double kBspPlaneDistance = 1e-6;

// The unit normal of planar polygon `poly` (Newell's method, exact in direction for a planar
// polygon; counter-clockwise seen from the normal's side). NaN components when the polygon has no
// area.
Vec3 polygon_normal(const std::vector<Vec3>& poly);

struct BspPortal {
  // The two leaves (map leaf numbers), leaves[0] < leaves[1].
  uint32_t leaves[2] = {0, 0};
  // The shared face: a convex polygon, Quake coordinates, counter-clockwise seen from leaves[1]
  // (its normal points from leaves[0] into leaves[1]).
  std::vector<Vec3> quake;
  // The same polygon in scene coordinates (quake_to_scene of each vertex; the rotation keeps the
  // winding).
  std::vector<Vec3> scene;
  // Its plane, Quake coordinates: unit normal from leaves[0] into leaves[1], dot(normal, p) =
  // offset.
  Vec3 normal{0, 0, 0};
  double offset = 0;
  double area = 0;  // square Quake units, >= kBspPortalMinArea
};

// The portals between the leaves `leaves` (map leaf numbers, increasing; their volumes are their
// non-empty pieces in `pieces`, bsp_leaf_pieces, each leaf's faces those of all its pieces in
// piece order): one per pair of them whose volumes share a face of at least kBspPortalMinArea, the
// overlap of the two faces (the face of leaves[0] clipped to the face of leaves[1]; the first such
// pair of faces in face order). Sorted by (leaves[0], leaves[1]). `leaves` must be increasing.
// Deterministic; O(leaves^2) box tests plus the faces of the pairs whose boxes touch.
std::vector<BspPortal> bsp_leaf_portals(const std::vector<BspLeafPiece>& pieces,
                                        const std::vector<uint32_t>& leaves);

// The leaves each of `leaves` may see, by base vis over `portals` (the file comment): for leaf L,
// L itself, each leaf across one of its portals, and every leaf reached from that leaf through
// portals q (in either direction, q's destination leaf next) such that q has a vertex more than
// kBspPlaneDistance in front of the first portal's plane (the side it leads into) and the first
// portal has a vertex more than kBspPlaneDistance behind q's plane (the side q comes from).
// `portals` must join only leaves of `leaves` (bsp_leaf_portals(pieces, leaves)). Result: one
// sorted list of map leaf numbers per entry of `leaves`, in its order. Deterministic whatever the
// thread count (TBB inside). O(portals^2 * vertices) plane tests and O(portals^2) flood steps.
std::vector<std::vector<uint32_t>> bsp_portal_base_vis(const std::vector<BspPortal>& portals,
                                                       const std::vector<uint32_t>& leaves);

}  // namespace vislib
