// footprint.h: conservative pixel footprints of a triangle seen from a moving eye
// (docs/visibility-math.md §5.1; the paper's ConvexHull, Alg. 1 line 6, made safe at the near
// plane).
//
// For a static triangle abc and an eye moving v0 -> v1, the eye-relative triangle at any t lies in
// W = conv{a-v0, b-v0, c-v0, a-v1, b-v1, c-v1}. The footprint on one cube face is the 2D convex
// hull of the projection of W clipped to z >= near (z = F.q, the face's view depth); pixel centres
// outside it are never covered. It is a superset: the coverage test decides exactly.
#pragma once

#include <array>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/vec.h"

namespace vislib {

struct Vec2 {
  double u = 0, w = 0;
};

// At most 12 input points and their 66 near-plane crossings; the hull of those has at most
// (12 + 66) vertices, fixed storage so that the hot loop allocates nothing.
constexpr int kMaxFootprintPoints = 12 + 66;

struct Footprint {
  // Convex polygon in face coordinates (u, w) = (S.q/F.q, T.q/F.q), counter-clockwise; may be a
  // point or a segment; empty when nothing of W lies at z >= near (invisible on this face).
  std::array<Vec2, kMaxFootprintPoints> hull;
  int size = 0;
  bool empty() const { return size == 0; }
};

// `rel` holds the eye-relative points (e.g. a-v0, ..., c-v1: any count up to 12); `axes` the
// world axes of the face. Returns the clipped, projected hull.
Footprint compute_footprint(const Vec3* rel, int count, const FaceAxes& axes, double near);
// The same hull written to `hull` (room for kMaxFootprintPoints); returns its size and sets
// `margin`, the margin footprint_row_span adds (computed once here instead of once per row).
int compute_footprint_hull(const Vec3* rel, int count, const FaceAxes& axes, double near,
                           Vec2* hull, double& margin);

// Pixel rectangle [x0,x1] x [y0,y1] (inclusive) of an N x N face containing every pixel centre
// in the box [umin, umax] x [wmin, wmax] of face coordinates widened by m on every side; false
// when none. The rectangles below (and the dynamic kernel's sphere bounds) all end here.
bool face_box_pixels(double umin, double umax, double wmin, double wmax, double m, int n, int& x0,
                     int& x1, int& y0, int& y1);

// Pixel rectangle [x0,x1] x [y0,y1] (inclusive) of an N x N face containing every pixel centre
// of the footprint (with kFootprintMargin); false when none.
bool footprint_pixel_bounds(const Footprint& fp, int n, int& x0, int& x1, int& y0, int& y1);

// The pixel rectangle of footprint_pixel_bounds(compute_footprint(rel, count, axes, near), ...)
// without building the hull: the hull's extreme coordinates are those of its input points, so the
// result is bit-identical at a fraction of the cost. `zmin` gets min F.rel[i] over the points.
bool footprint_bounds(const Vec3* rel, int count, const FaceAxes& axes, double near, int n, int& x0,
                      int& x1, int& y0, int& y1, double& zmin);

// A rectangle containing footprint_bounds of every triangle inside the box [lo, hi] (world
// coordinates) seen from the segment v0 -> v1, and `zmin` below each such triangle's zmin: the
// bounds of a BVH node (triangle_bvh.h). False when no such triangle can reach the face. The
// whole face when the box reaches the near plane.
bool box_footprint_bounds(const float lo[3], const float hi[3], Vec3 v0, Vec3 v1,
                          const FaceAxes& axes, double near, int n, int& x0, int& x1, int& y0,
                          int& y1, double& zmin);

// Bit k set for every cube face k (orientation R) on which footprint_bounds / compute_footprint
// of the same points may be non-empty: the faces that their quick frustum reject does not
// exclude, decided for all six faces from one set of dot products (bit-identical to the per-face
// test). Lets a kernel skip the per-face work of a primitive on the faces it cannot reach.
unsigned reachable_faces(const Vec3* rel, int count, const Mat3& R, double near);

// Columns [x0, x1] of row `y` whose centres may lie in the footprint; false when none.
bool footprint_row_span(const Footprint& fp, int n, int y, int& x0, int& x1);
// The same for a hull of `size` points with its margin (compute_footprint_hull).
bool footprint_row_span(const Vec2* hull, int size, double margin, int n, int y, int& x0, int& x1);

}  // namespace vislib
