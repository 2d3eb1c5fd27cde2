// triangle_groups.h: consecutive triangles that form one convex planar polygon (a fan), which the
// static kernel composites as one primitive and reports as its triangles
// (docs/visibility-math.md §2.6).
//
// Map compilers and mesh importers fan-triangulate convex faces: face F with corners v0 ... vk
// becomes the triangles (v0, vi, vi+1). Along a pixel ray the eye's moving hit point crosses the
// fan's inner edges, and composited triangle by triangle each crossing is a piece boundary: on the
// LibreQuake maps 42% of a bake's final pieces continue a piece of the same face (measured over
// lqdm1 leaves 1-321/40 at N = 128), and the insertions that made them are 1.76 times the
// (face, pixel) pairs. A group is composited as the polygon (its boundary edges, its plane) and
// each of its final pieces is split back at the inner edges into the pieces its triangles would
// have had: the same cuts (the inner edge's coefficients, computed as the triangle kernel computes
// them), so the visible triangles and their witnesses are the triangle kernel's, up to rounding
// in the depth functions (one plane for the group instead of one per triangle).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A group's corners: at most this many (a fan of 4 triangles), so that the footprint of its
// corners at both ends of a segment fits the footprint's 12 input points (footprint.h).
constexpr int kMaxGroupCorners = 6;

// Largest distance of a corner from the plane of the group's first triangle, relative to the
// group's extent (the largest coordinate difference of its corners), for the group to be
// composited in that plane. A map's corners are floats, so its faces are planar to about 1e-9 of
// their size (lqdm1: 353 of 2,053 adjacent fan triangles between 1e-10 and 1e-9, none between
// 1e-9 and 1e-6); a 256-unit face is then off its triangles' planes by at most 2.6e-7 units,
// under the depth tie tolerance (SegmentOptions::eps_z, 1e-6 relative by default) at depths
// beyond 0.26 units.
constexpr double kGroupPlaneTolerance = 1e-9;

struct TriangleGroups {
  // Group g is the triangles first[g] ... first[g + 1] - 1 (consecutive ids); first.back() is the
  // triangle count. Empty: every triangle is its own group.
  std::vector<uint32_t> first;

  size_t count(size_t triangle_count) const {
    return first.empty() ? triangle_count : first.size() - 1;
  }
  uint32_t begin(uint32_t g) const { return first.empty() ? g : first[g]; }
  uint32_t end(uint32_t g) const { return first.empty() ? g + 1 : first[g + 1]; }
};

// The fans of `scene` in key state `state`: runs of consecutive triangles of one opaque object
// where triangle t + 1 is (a, c, d) after t = (a, b, c) (vertex indices), every triangle has a
// non-zero normal in the same direction, the polygon a, b, c, d, ... is convex (a corner on a
// straight edge only where its two edges are exactly collinear), its corners lie within
// kGroupPlaneTolerance of the first triangle's plane, and it has at most kMaxGroupCorners corners
// (a longer fan is cut into groups that are). Dynamic scenes and see-through objects: none.
// Deterministic, O(triangles).
TriangleGroups build_triangle_groups(const Scene& scene, size_t state = 0);

// Writes the corners of group [first, end) of a fan (a, b, c, then each next triangle's third
// corner) to `out` (room for kMaxGroupCorners) and returns their count (end - first + 2).
int group_corners(const Scene& scene, size_t state, uint32_t first, uint32_t end, Vec3* out);

}  // namespace vislib
