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

// The view region of a leaf whose volume is `leaf_volume` (not empty): the volume inset by
// kBspLeafInset; a leaf too thin for that (nothing left) is inset by the largest of
// kBspLeafInset / 2^k, k = 1, 2, ..., down to kBspLeafMinInset, that leaves a volume, and by 0
// (the volume itself) when none does. `inset` is the distance used.
struct BspViewRegion {
  ConvexPolytope volume;
  double inset = 0;
};
BspViewRegion bsp_leaf_view_region(const ConvexPolytope& leaf_volume);

}  // namespace vislib
