// quake_bsp_volumes.h: the volumes of a Quake map's BSP leaves (quake_bsp.h) as convex polytopes:
// the world model's bounds (model 0's mins/maxs) clipped by the node planes on the path from the
// root to the leaf. Quake coordinates (z up), double precision.
//
// Every path end of model 0's tree is one piece; leaf 0 (solid) ends many paths and so has many
// pieces, every other leaf exactly one in a map whose leaves are reached once. The pieces
// partition the bounds: they are disjoint up to their shared boundaries and their volumes sum to
// the box's.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/quake_bsp.h"

namespace vislib {

// A half-space dot(normal, p) <= offset.
struct HalfSpace {
  Vec3 normal;
  double offset = 0;
};

// A convex polytope given by its half-spaces (the box's six, then the path's planes from the root
// down) and its boundary: one polygon per half-space that bounds it with positive area, vertices
// counter-clockwise seen from outside. Empty (no faces) when the half-spaces leave no volume.
struct ConvexPolytope {
  std::vector<HalfSpace> halfspaces;
  std::vector<std::vector<Vec3>> faces;
  bool empty() const { return faces.empty(); }
  // Volume by the divergence theorem over the faces (0 when empty).
  double volume() const;
  // Bounding box of the face vertices (empty when the polytope is).
  Box3 bounds() const;
};

struct BspLeafPiece {
  uint32_t leaf = 0;  // the leaf this path ends in
  ConvexPolytope volume;
};

// The pieces of model 0's tree, one per path end, in depth-first order (front child first).
// A node's front child keeps dot(normal, p) - dist > 0 (the walk of bsp_point_leaf), its back child
// the rest; the polytope's half-spaces are closed, so neighbouring pieces share their boundary.
// Clipping compares with 0 exactly (no tolerance): a polygon clipped to fewer than 3 vertices
// ends. Deterministic. O(pieces * depth^2) polygon clips.
std::vector<BspLeafPiece> bsp_leaf_pieces(const QuakeBsp& bsp);

// `p` with every half-space moved inward by `distance` (Quake units, >= 0): dot(n, x) <= offset -
// distance * |n|. Empty when nothing of positive volume is left. `p.faces` may be empty (the
// half-spaces alone, bounded: a box's six among them), so this also builds a polytope's faces.
ConvexPolytope inset_polytope(const ConvexPolytope& p, double distance);

// How far inside its leaf's volume a cell's view region lies (Quake units): eyes exactly on a
// leaf's boundary would sit on the faces that lie there, and a point of a boundary plane belongs
// to one side only (bsp_point_leaf), so the region keeps this distance from every plane.
constexpr double kBspLeafInset = 1.0;
// The smallest inset tried for a leaf too thin for kBspLeafInset (Quake units).
constexpr double kBspLeafMinInset = 1.0 / 64;

// An eye must lie at least this many near distances from every surface (unitless): a point at
// distance r from the eye has view-space depth at least r / sqrt(3) on the cube-map face it
// projects to (its largest coordinate in any orthonormal frame is at least r / sqrt(3)), so a
// surface that far or farther is never cut by the near plane, and never seen through
// (docs/visibility-math.md "The near plane and the view region").
constexpr double kNearClearanceFactor = 1.7320508075688772;

// The view region of a leaf whose volume is `leaf_volume` (not empty), for a bake whose near
// distance is `near` (> 0, Quake units). Its boundary faces hold the world's surfaces, so every eye
// of the region keeps a clearance c = kNearClearanceFactor * near from every plane of the volume:
//  - the volume inset by the largest of max(kBspLeafInset, c) / 2^k, k = 0, 1, ..., that is at
//    least max(kBspLeafMinInset, c) and leaves a volume, else by exactly c if that leaves one;
//  - a leaf thinner than 2c (nothing is left at c) is inset by half of the largest inset that
//    leaves a volume (found by bisection), and the near distance of its runs is clipped to
//    near_limit = inset / kNearClearanceFactor, so that its eyes still see no surface cut by the
//    near plane;
//  - a volume that leaves nothing at any inset tried (none of positive volume does) is its own
//    region with inset 0 and no limit.
// `inset` is the distance used; near_limit is +infinity unless the near distance is clipped.
struct BspViewRegion {
  ConvexPolytope volume;
  double inset = 0;
  double near_limit = std::numeric_limits<double>::infinity();
};
BspViewRegion bsp_leaf_view_region(const ConvexPolytope& leaf_volume, double near);

}  // namespace vislib
