// segment_visibility.h: continuous from-segment visibility for static triangles.
//
// Implements §3.1 (Alg. 1) of "Complex VEs on All-In-One VR Headsets Through Continuous
// From-Segment Visibility Computation" as specified in shared/design/visibility-math.md
// (§1-2 coverage, §5.1 footprint, §6 numerics, §7 compositing): for every pixel centre of a
// cubemap that translates (without rotating) along v(t) = v0 + t(v1 - v0), t in [0,1], the exact
// list of pieces of t during which each triangle is the first hit (lambda > near), composited by
// depth; a triangle is visible when it owns a final piece longer than eps_len.
//
// Arithmetic: coordinates are re-centred at v0 and everything is double; coverage uses 3D triple
// products with canonically oriented edges (bit-identical on shared edges, so closed meshes do not
// leak) and the symbolic-perturbation tie rule of §2.5. Deterministic: the result (ids, witnesses,
// pieces) is identical for any thread count and any triangle input order (ids mapped back).
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/cubemap.h"
#include "vislib/interval_list.h"
#include "vislib/scene.h"
#include "vislib/tolerances.h"

namespace vislib {

// How animation time relates to the eye's motion in a dynamic scene (docs/visibility.md):
//  Diagonal (the paper's mode): scene time tau and the segment parameter t advance together
//    (tau = t), one space-time diagonal per state interval;
//  Decoupled (what a VR user needs, any eye position at any time): the diagonal plus the boundary
//    of the (t, tau) square: the eye fixed at each segment end while the scene animates, and the
//    scene frozen at each key state while the eye moves. An approximation of the full square, as
//    the perimeter is of a view rectangle.
enum class DynamicMode { Diagonal, Decoupled };

struct SegmentOptions {
  int resolution = 512;             // N: each cube face is N x N pixels; must be >= 1
  double near = kDefaultNear;       // z_near > 0, view depth in scene units
  Mat3 orientation;                 // cube orientation R (world = R * local); a rotation
  double eps_len = kDefaultEpsLen;  // final pieces must be longer (in t) to count
  bool want_witnesses = false;      // one witness per visible triangle
  bool want_pieces = false;         // keep every pixel's final list (memory: 6 N^2 lists)
  int tile_size = 32;               // pixels per tile side (memory/parallelism grain)
  bool depth_culling = true;        // skip hidden work (exact): triangles behind a tile's or a
                                    // pixel's covered depth, intervals behind the pixel's
                                    // depth envelope over t
  bool simd = true;                 // vectorised coverage where the CPU has AVX2 (results
                                    // bit-identical to the scalar path)
  size_t state = 0;                 // static scenes: which key state to use
  DynamicMode mode = DynamicMode::Diagonal;  // dynamic scenes (moving vertices or spheres)
};

// A pixel and a t at which `tri` is the first hit: the middle of its longest final piece
// (ties: lowest face, then row, then column).
struct Witness {
  uint32_t tri = 0;  // triangle id, or sphere index when is_sphere
  bool is_sphere = false;
  int face = 0, x = 0, y = 0;
  double t = 0;    // eye at v0 + t (v1 - v0)
  double tau = 0;  // animation time in [0,1] (static scenes: 0)
};

struct SegmentStats {
  uint64_t pair_tests = 0;     // (triangle, pixel) coverage evaluations
  uint64_t culled_pairs = 0;   // (triangle, pixel) pairs skipped by per-pixel depth culling
  uint64_t covered_pairs = 0;  // of which gave a non-empty interval
  uint64_t hidden_pairs = 0;   // of which were behind the pixel's depth envelope (not inserted)
  uint64_t final_pieces = 0;   // pieces in all final lists
  uint64_t pixels_with_pieces = 0;
  uint64_t max_pieces_per_pixel = 0;
  uint64_t triangle_tiles = 0;         // (triangle, tile) pairs binned
  uint64_t culled_triangle_tiles = 0;  // of which skipped by depth culling
  double peak_tile_bytes = 0;          // largest memory held by one tile's pixel lists
  double seconds = 0;                  // wall time of the call
  // Adds another part's counts (maxima for the max fields).
  void add(const SegmentStats& o) {
    pair_tests += o.pair_tests;
    culled_pairs += o.culled_pairs;
    covered_pairs += o.covered_pairs;
    hidden_pairs += o.hidden_pairs;
    final_pieces += o.final_pieces;
    pixels_with_pieces += o.pixels_with_pieces;
    max_pieces_per_pixel = max_pieces_per_pixel > o.max_pieces_per_pixel ? max_pieces_per_pixel
                                                                         : o.max_pieces_per_pixel;
    triangle_tiles += o.triangle_tiles;
    culled_triangle_tiles += o.culled_triangle_tiles;
    peak_tile_bytes = peak_tile_bytes > o.peak_tile_bytes ? peak_tile_bytes : o.peak_tile_bytes;
  }
  double pieces_per_pixel() const {
    return pixels_with_pieces ? double(final_pieces) / double(pixels_with_pieces) : 0.0;
  }
};

// Depth along a pixel ray in the dynamic kernel (math note §3.2, §4): a rational N(t)/D(t)
// (cubic over quadratic; static triangles have degrees 1 and 0) or a sphere's near or far root.
struct GeneralDepth {
  enum Kind : uint8_t { Rational, SphereNear, SphereFar };
  Kind kind = Rational;
  // Rational: N0..N3 then D0..D2. Sphere: h0 h1 (d.w), m0 m1 m2 (|w|^2 - r^2), g0 g1 g2
  // (r^2|d|^2 - |d x w|^2), |d|^2, then w0 (3), w1 (3) and r of w(t) = eye(t) - centre(t), used
  // to skip the crossing search for spheres that stay disjoint (math note §4).
  double c[16] = {};
  double at(double t) const;
};
// Crossings of two depths inside (lo, hi), pair in id order, as polynomial roots (isolated on
// monotone pieces, bisected): P = N_i D_j - N_j D_i for two triangles (degree <= 5); for spheres,
// the condition that the ray's point at the common depth lies on both surfaces (degree 4
// sphere-sphere, 6 sphere-triangle). Spheres that stay disjoint over the run have none.
int depth_crossings(const GeneralDepth& i, const GeneralDepth& j, double lo, double hi,
                    double* out);
using GeneralPiece = PieceT<GeneralDepth>;

struct SegmentResult {
  std::vector<uint32_t> visible;          // sorted triangle ids
  std::vector<uint32_t> visible_spheres;  // sorted sphere indices (dynamic kernel)
  std::vector<Witness> witnesses;         // if requested: one per visible id, in id order
  // If requested: final list of pixel (face, x, y) at index (face * N + y) * N + x.
  std::vector<PieceList> pieces;
  // If requested, for dynamic scenes in Diagonal mode (instead of `pieces`): same indexing; ids
  // are triangle ids, and triangle_count + s for sphere s. t0, t1 are on the whole segment; each
  // depth function stays in the local parameter of its state interval [t_k, t_k+1] (evaluate it
  // at (t - t_k) / (t_k+1 - t_k), with t_k = k / (states - 1)).
  std::vector<std::vector<GeneralPiece>> general_pieces;
  SegmentStats stats;
};

// Visibility of the scene's triangles and spheres from the segment v0 -> v1. A static scene
// without spheres takes the linear path (key state `options.state`); a scene with moving vertices
// or spheres takes the dynamic kernel (dynamic_visibility.cpp; quadratic events only for what
// moves) in `options.mode`. Thread-safe (reads the scene only); parallel with TBB.
SegmentResult segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1,
                                 const SegmentOptions& options);

// The dynamic kernel alone (also for static scenes, e.g. to compare both paths in tests).
SegmentResult dynamic_segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1,
                                         const SegmentOptions& options);

// ---- The steps, exposed for tests ----------------------------------------------------------

// Per-triangle quantities of §2 for one segment, re-centred at v0.
struct StaticTriangle {
  Vec3 KA[3], KB[3];  // per edge ab, bc, ca: (Q-P) x Delta and (Q-P) x (v0-P), canonical P<Q
  double rho[3];      // +1 if the triangle runs P->Q, else -1
  Vec3 n;             // (b-a) x (c-a)
  double N0, N1;      // n.(a-v0), n.Delta
};
StaticTriangle prepare_static_triangle(const Vec3 corners[3], Vec3 v0, Vec3 v1);

// Coverage interval [lo, hi) and depth of a prepared triangle at pixel direction d (world,
// un-normalised) with face axes S, T used by the tie rule. False when empty.
bool static_coverage(const StaticTriangle& tri, Vec3 d, Vec3 S, Vec3 T, double near, double& lo,
                     double& hi, LinearDepth& depth);

}  // namespace vislib
