// general_depth.h: the depth functions of the dynamic kernel (docs/visibility-math.md §3.2, §4) and
// their crossings, the depth type of its per-pixel lists (interval_list.h).
#pragma once

#include <cstdint>

#include "vislib/kernel/interval_list.h"

namespace vislib {

// Depth along a pixel ray in the dynamic kernel (docs/visibility-math.md §3.2, §4): a rational
// N(t)/D(t) (cubic over quadratic; static triangles have degrees 1 and 0) or a sphere's near or far
// root.
struct GeneralDepth {
  enum Kind : uint8_t { Rational, SphereNear, SphereFar };
  Kind kind = Rational;
  // Rational: N0..N3 then D0..D2. Sphere: h0 h1 (d.w), m0 m1 m2 (|w|^2 - r^2), g0 g1 g2
  // (r^2|d|^2 - |d x w|^2), |d|^2, then w0 (3), w1 (3) and r of w(t) = eye(t) - centre(t), used
  // to skip the crossing search for spheres that stay disjoint (docs/visibility-math.md §4).
  double c[16] = {};
  double at(double t) const;
};
// Crossings of two depths inside (lo, hi), pair in id order, as polynomial roots (isolated on
// monotone pieces, bisected): P = N_i D_j - N_j D_i for two triangles (degree <= 5); for spheres,
// the condition that the ray's point at the common depth lies on both surfaces (degree 4
// sphere-sphere, 6 sphere-triangle). Spheres that stay disjoint over the run have none.
int depth_crossings(const GeneralDepth& i, const GeneralDepth& j, double lo, double hi,
                    double* out);
// Same kind (rational, sphere near root, sphere far root) and same coefficients.
bool same_depth(const GeneralDepth& a, const GeneralDepth& b);
using GeneralPiece = PieceT<GeneralDepth>;

}  // namespace vislib
