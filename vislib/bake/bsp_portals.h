// bsp_portals.h: the portals between a Quake map's BSP leaves, and what a leaf sees of itself.
//
// The map file holds no portals (the compiler keeps them in a separate .prt file), so they are
// found from the leaf volumes (quake_bsp_volumes.h): two leaves are neighbours when a face of one
// and a face of the other lie on one plane with opposite normals and overlap with positive area
// (at least kBspPortalMinArea square units); the overlap is their portal, the part of a node's
// plane where the two leaves meet, as the compiler would write it.
//
// An eye inside a leaf looks either at the leaf's own boundary (a wall, where the scene's faces
// lie, or a portal) or at something inside the leaf (a door, a platform: models other than the
// world's), or through a portal. What it sees through a portal q, it sees from q in the same
// direction (the leaf is convex), so a leaf's set is the union of what its portals see in the
// directions that leave it and of the triangles on or in its volume (bsp_volume_triangles).
// docs/quake.md "Portals" says why this is exact and what it assumes.
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/quake_bsp_volumes.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Two leaf volumes are neighbours when their shared face has at least this area (square Quake
// units; a real portal is at least about 1).
constexpr double kBspPortalMinArea = 1e-3;
// Points within this distance of a plane (Quake units) lie on it, for the faces two leaf volumes
// share: they come from the same float planes and agree to about 1e-12 units.
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
  std::vector<Vec3> polygon;
  // Unit normal of its plane, from leaves[0] into leaves[1] (Quake coordinates).
  Vec3 normal{0, 0, 0};
  double area = 0;  // square Quake units, >= kBspPortalMinArea
};

// The portals between the leaves `leaves` (map leaf numbers, increasing; their volumes are their
// non-empty pieces in `pieces`, bsp_leaf_pieces, each leaf's faces those of all its pieces in
// piece order): one per pair of them whose volumes share a face of at least kBspPortalMinArea, the
// overlap of the two faces (the face of leaves[0] clipped to the face of leaves[1]; the first such
// pair of faces in face order). Sorted by (leaves[0], leaves[1]). Deterministic; O(leaves^2) box
// tests plus the faces of the pairs whose boxes touch.
std::vector<BspPortal> bsp_leaf_portals(const std::vector<BspLeafPiece>& pieces,
                                        const std::vector<uint32_t>& leaves);

// A triangle lies on a face of a leaf volume when each of its corners is within this distance of
// the face's plane (Quake units): a map's vertices are floats, which round coordinates of a few
// thousand units by up to about 2.5e-4, and the compiler snaps them to 1/8 unit or so.
constexpr double kBspOnFaceDistance = 0.05;
// A triangle's part inside a leaf volume, or on one of its faces, counts only where it is wider
// than this (Quake units): the volume's planes are moved inward by it before the triangle is
// clipped, so that a triangle that only touches the volume along an edge or at a corner (the next
// leaf's wall) does not count. A part narrower than this is under a pixel at any eye the bake
// samples and is left to the portals' runs, which see it when they can (docs/quake.md "Portals").
constexpr double kBspOwnMinWidth = 1e-3;

// A triangle of the scene that an eye inside a volume may see without a portal, and a point of it
// on or in the volume (the centre of its part there, for a witness ray).
struct VolumeTriangle {
  uint32_t tri = 0;
  Vec3 point;
};

// The triangles (key state `state`) of `scene` with a part wider than kBspOwnMinWidth inside
// `volume`, or on one of its faces (corners within kBspOnFaceDistance of the face's plane, part
// inside the face's other planes moved inward), in increasing id. `volume`: scene coordinates
// (quake_to_scene is a rotation, so a polytope maps plane for plane). Deterministic.
std::vector<VolumeTriangle> bsp_volume_triangles(const Scene& scene, const ConvexPolytope& volume,
                                                 size_t state = 0);

// `p` (Quake coordinates) in scene coordinates (quake_to_scene of its normals and vertices).
ConvexPolytope polytope_to_scene(const ConvexPolytope& p);

// The part of portal `portal` whose points keep at least `clearance` (Quake units) from every
// plane of the two volumes `a` and `b` (its leaves' volumes, Quake coordinates) but the portal's
// own: an eye there sees no wall next to the portal cut by a near plane at clearance /
// kNearClearanceFactor (quake_bsp_volumes.h). Empty when nothing of positive area is left.
std::vector<Vec3> bsp_portal_clear_part(const BspPortal& portal, const ConvexPolytope& a,
                                        const ConvexPolytope& b, double clearance);

// The opaque triangles of `scene` that lie on a portal's plane (corners within
// kBspOnFaceDistance; the scene's coordinates are quake_to_scene of the map's): a floor or a
// liquid's opaque surface laid over the portal. An eye of the portal inside such a part would see
// through the surface (it lies at depth 0, cut by any near plane), so the part is not swept.
struct BspPortalCover {
  // Each such triangle's overlap with the portal but for a band kBspOwnMinWidth wide along the
  // portal's edges, Quake coordinates, in increasing triangle id (those with no overlap of
  // positive area left out). The band is under a pixel at any eye the bake samples, and holds the
  // slivers of the faces next to the portal (its corners come from float planes and miss the
  // faces' corners by up to about 1e-4 units).
  std::vector<std::vector<Vec3>> parts;
  // The parts cover the portal but for the band (or the portal is narrower than twice the band):
  // it is closed, both leaves see the surface (on their faces) and nothing through it.
  bool closed = false;
};
BspPortalCover bsp_portal_cover(const BspPortal& portal, const Scene& scene);

// The pieces of segment `s` (on the plane of `portal`, Quake coordinates) that keep at least
// `clearance` (Quake units, >= 0) from every part of `cover`, in the plane: in order from s.from,
// each a sub-segment of s longer than `min_length`; s itself when the cover has no parts.
std::vector<Segment> bsp_portal_open_pieces(const Segment& s, const BspPortal& portal,
                                            const BspPortalCover& cover, double clearance,
                                            double min_length);

}  // namespace vislib
