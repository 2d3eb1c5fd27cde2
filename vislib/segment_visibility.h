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

struct SegmentOptions {
  int resolution = 512;                   // N: each cube face is N x N pixels; must be >= 1
  double near = kDefaultNear;             // z_near > 0, view depth in scene units
  Mat3 orientation;                       // cube orientation R (world = R * local); a rotation
  double eps_len = kDefaultEpsLen;        // final pieces must be longer (in t) to count
  bool want_witnesses = false;            // one witness per visible triangle
  bool want_pieces = false;               // keep every pixel's final list (memory: 6 N^2 lists)
  int tile_size = 32;                     // pixels per tile side (memory/parallelism grain)
  bool depth_culling = true;              // skip triangles behind a tile's fully covered pixels
  size_t state = 0;                       // which key state of the scene to use
};

// A pixel and a t at which `tri` is the first hit: the middle of its longest final piece
// (ties: lowest face, then row, then column).
struct Witness {
  uint32_t tri = 0;
  int face = 0, x = 0, y = 0;
  double t = 0;
};

struct SegmentStats {
  uint64_t pair_tests = 0;         // (triangle, pixel) coverage evaluations
  uint64_t culled_pairs = 0;       // (triangle, pixel) pairs skipped by per-pixel depth culling
  uint64_t covered_pairs = 0;      // of which gave a non-empty interval
  uint64_t final_pieces = 0;       // pieces in all final lists
  uint64_t pixels_with_pieces = 0;
  uint64_t max_pieces_per_pixel = 0;
  uint64_t triangle_tiles = 0;     // (triangle, tile) pairs binned
  uint64_t culled_triangle_tiles = 0;  // of which skipped by depth culling
  double peak_tile_bytes = 0;      // largest memory held by one tile's pixel lists
  double seconds = 0;              // wall time of the call
  double pieces_per_pixel() const {
    return pixels_with_pieces ? double(final_pieces) / double(pixels_with_pieces) : 0.0;
  }
};

struct SegmentResult {
  std::vector<uint32_t> visible;     // sorted triangle ids
  std::vector<Witness> witnesses;    // if requested: one per visible id, in id order
  // If requested: final list of pixel (face, x, y) at index (face * N + y) * N + x.
  std::vector<PieceList> pieces;
  SegmentStats stats;
};

// Visibility of the scene's triangles (key state `options.state`) from the segment v0 -> v1.
// Spheres are ignored here. Thread-safe (reads the scene only); parallel with TBB.
SegmentResult segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1, const SegmentOptions& options);

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
