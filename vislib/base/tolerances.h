// tolerances.h: every tolerance of the visibility kernels, named, with its unit and the direction
// in which it errs (house style §5). Predicates themselves compare with 0 exactly
// (docs/visibility-math.md §6).
#pragma once

namespace vislib {

// Final pieces of a pixel's list shorter than this (in segment parameter t, unitless in [0,1]) do
// not make their triangle visible. Removes T-junction leaks of ~1e-16 (docs/visibility-math.md
// §2.5, §7). Errs towards hidden for pieces that short; 0 = exact mode.
constexpr double kDefaultEpsLen = 1e-12;

// Depth tie tolerance eps_z (docs/visibility-math.md §7, H9), relative (unitless): where two
// surfaces covering a pixel have view depths within eps_z * lambda of each other (lambda = the
// front depth; 1e-6 is 1 micrometre at 1 m, 0.1 mm at 100 m), both count as visible, as a headset's
// z-buffer may show either (z-fighting). Makes coplanar overlaps (decals, doubled walls)
// independent of placement, rotation and units. Errs towards visible; 0 = exactly equal depths
// only.
constexpr double kDefaultEpsZ = 1e-6;

// Margin added around a footprint in face coordinates (u, w) in [-1,1] (one pixel = 2/N). Errs
// towards scanning more pixels (safe: coverage is decided exactly afterwards).
constexpr double kFootprintMargin = 1e-6;

// Relative part of the footprint margin: the margin grows by this share of the largest |u| or |w|
// of the footprint's points (face coordinates; points near the near plane project far out and their
// rounding grows with them). Unitless, relative. Errs towards scanning more pixels (safe).
constexpr double kFootprintRelativeMargin = 1e-12;

// Quick reject of a primitive against a face's frustum: the planes |u| <= 1 and |w| <= 1 are
// widened by this relative share of the point's depth (unitless) before all points are tested to
// lie outside one plane. Errs towards keeping primitives (the exact clip decides afterwards).
constexpr double kFrustumRejectWidening = 1e-6;

// Two moving spheres whose centres stay farther apart than (1 + this) times the sum of their radii
// (relative, unitless) keep their depth order, and their crossing search is skipped
// (docs/visibility-math.md §4). Errs towards searching (a pair within the band is searched
// exactly).
constexpr double kDisjointSpheresSlack = 1e-9;

// Default near plane: view-space depth (scene units, metres for our scenes) below which hits do
// not count; a typical headset near plane.
constexpr double kDefaultNear = 0.01;

// Walkable cells (view_cells.h): a floor piece (the part of a floor triangle inside a column)
// smaller than this fraction of the column's area (cell_size^2) does not make a cell; removes
// zero-area slivers of triangles that only touch the column's border. Errs towards fewer cells.
constexpr double kMinFloorAreaFraction = 1e-9;

// Walkable cells: heights closer than this fraction of cell_size count as the same height in the
// headroom test (a building's bottom face lying on the ground covers it). Errs towards keeping
// cells (a surface just above the floor may be taken for the floor itself).
constexpr double kFloorHeightTolerance = 1e-6;

// Pixel error epsilon (metrics.h, paper §4.3): a pixel of a frame rendered from a visible set
// counts as missed when its depth exceeds the ground-truth depth by more than this share of the
// ground-truth depth (relative, unitless). Embree returns depths in float (relative error ~1e-7),
// and two surfaces that meet at the pixel (shared edges, coplanar overlays) may then swap; a
// surface this close behind the true one is not counted as a miss. Errs towards "not missed" for
// surfaces within 0.01% behind the visible one.
constexpr double kPixelErrorDepthTolerance = 1e-4;

}  // namespace vislib
