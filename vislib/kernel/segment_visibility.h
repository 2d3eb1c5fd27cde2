// segment_visibility.h: continuous from-segment visibility for static triangles.
//
// Implements §3.1 (Alg. 1) of "Complex VEs on All-In-One VR Headsets Through Continuous
// From-Segment Visibility Computation" as specified in docs/visibility-math.md
// (§1-2 coverage, §5.1 footprint, §6 numerics, §7 compositing): for every pixel centre of a
// cubemap that translates (without rotating) along v(t) = v0 + t(v1 - v0), t in [0,1], the exact
// list of pieces of t during which each triangle is the first hit (lambda > near), composited by
// depth; a triangle is visible when it owns a final piece longer than eps_len.
//
// Arithmetic: coordinates are re-centred at v0 and everything is double; coverage uses 3D triple
// products with canonically oriented edges (bit-identical on shared edges, so closed meshes do not
// leak) and the symbolic-perturbation tie rule of §2.5. Deterministic: the result (ids, witnesses,
// pieces) is identical for any thread count, tile order and with or without a BVH. (Renumbering
// the triangles changes the order of insertion among equal depths, which can change the tiny
// pieces at triple depth crossings: interval_list.h.)
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/tolerances.h"
#include "vislib/kernel/edge_lines.h"
#include "vislib/kernel/general_depth.h"
#include "vislib/kernel/interval_list.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/kernel/witness.h"
#include "vislib/scene/scene.h"

namespace vislib {

// How animation time relates to the eye's motion in a dynamic scene (docs/visibility.md):
//  Diagonal (the paper's mode): scene time tau and the segment parameter t advance together
//    (tau = t), one space-time diagonal per state interval;
//  Decoupled (what a VR user needs, any eye position at any time): the diagonal plus the boundary
//    of the (t, tau) square: the eye fixed at each segment end while the scene animates, and the
//    scene frozen at each key state while the eye moves. An approximation of the full square, as
//    the perimeter is of a view rectangle.
enum class DynamicMode { Diagonal, Decoupled };

// Depth ties between surfaces (docs/visibility-math.md §7, H9, docs/visibility.md "Coplanar
// surfaces"):
//  Both: where the loser of a depth test lies within eps_z (relative) of the winner over a stretch
//    of the segment, both are visible there (a z-buffer z-fights); the default.
//  First: the nearer depth wins and exact ties go to the lower id; the set then
//    depends on rounding, hence on placement and units, for coplanar overlaps.
enum class CoplanarRule { Both, First };

// Default tile sides (SegmentOptions::tile_size = 0). The dynamic kernel's pixel lists point
// into a per-tile pool of depth functions (136 bytes each), which a smaller tile keeps in cache:
// the grass field at N = 512 on one core is about 1.2x faster with 16 than with 32 and needs
// 2.5x less memory; the static cases are slower with 16 (docs/performance.md).
constexpr int kStaticTileSize = 32;
constexpr int kDynamicTileSize = 16;
// The largest tile side taken from a user or a file (pixels): a thread's tile scratch holds
// tile_size^2 pixel lists, so this bounds what one bad number can allocate (about 400 MB of
// empty lists at 4096).
constexpr int kMaxTileSize = 4096;

// Tiles along a cube face's side at resolution `n` and tile side `tile_size` (> 0).
constexpr int tiles_per_side(int n, int tile_size) {
  return (n + tile_size - 1) / tile_size;
}

// The index of tile (x, y) of cube face `face` in a tile mask (SegmentOptions::tile_mask) of
// `tiles` tiles a side: face-major, then row-major.
constexpr size_t tile_mask_index(int face, int x, int y, int tiles) {
  return (size_t(face) * size_t(tiles) + size_t(y)) * size_t(tiles) + size_t(x);
}

// The most planes one run splits its directions by (SegmentOptions::more_side_normals): two marks
// a plane in an id's 8 bits.
constexpr size_t kMaxSidePlanes = 4;

struct SegmentOptions {
  int resolution = 512;             // N: each cube face is N x N pixels; must be >= 1
  double near = kDefaultNear;       // z_near > 0, view depth in scene units
  Mat3 orientation;                 // cube orientation R (world = R * local); a rotation
  double eps_len = kDefaultEpsLen;  // final pieces must be longer (in t) to count
  bool want_witnesses = false;      // one witness per visible triangle
  bool want_pieces = false;         // keep every pixel's final list (memory: 6 N^2 lists)
  int tile_size = 0;  // pixels per tile side (memory/parallelism grain); 0: the kernel's choice,
                      // kStaticTileSize, or kDynamicTileSize with moving triangles or spheres
  bool depth_culling = true;  // skip hidden work (exact): triangles behind a tile's or a pixel's
                              // covered depth, intervals behind a covered pixel's one piece
  bool simd = true;           // vectorised coverage where the CPU has AVX2 (bit-identical results)
  size_t state = 0;           // static scenes: which key state to use
  DynamicMode mode = DynamicMode::Diagonal;    // dynamic scenes (moving vertices or spheres)
  CoplanarRule coplanar = CoplanarRule::Both;  // depth ties: both visible, or the first (lower id)
  double eps_z = kDefaultEpsZ;                 // tie tolerance, relative to the front depth; >= 0
  // Split points of a long segment (static scenes only): 0 < s_1 < ... < 1, at
  // most kMaxSplitParts - 1 of them. Part i is [s_i, s_i+1] (s_0 = 0, s_m = 1); a triangle is
  // visible from part i when it owns a final piece whose overlap with the part is longer than
  // eps_len times the part's length, the test a run over that part alone makes. The result then
  // holds visible_parts; witnesses are not kept per part (want_witnesses gives the whole
  // segment's).
  std::vector<double> splits;
  // Static scenes: a BVH of the scene's triangles in key state `state` (build_triangle_bvh), so
  // that each tile walks the tree front to back instead of every triangle getting footprint
  // bounds on every face. Null: no tree. The results are the same either way when the tree's
  // primitives are what `fans` asks for; a tree built for another scene or state is refused
  // (std::invalid_argument).
  const TriangleBvh* bvh = nullptr;
  // Static scenes: composite the scene's fans as polygons (triangle_groups.h, the same visible
  // sets but for ties at corners: docs/visibility-math.md §2.6), or its triangles one by one.
  // With a tree, its primitives decide (BvhPrimitives).
  bool fans = true;
  // Static scenes: the runs of collinear edges (build_edge_lines), so that T-junctions do not leak
  // (edge_lines.h). Null: the kernel builds them for the call (the same results; callers running
  // many segments on one scene build them once). Built for another scene or state: refused
  // (std::invalid_argument).
  const EdgeLines* edge_lines = nullptr;
  // Directions split by a plane through the eye (static scenes; not with `splits`): when
  // `side_normal` is not zero, a pixel whose world direction d has dot(d, side_normal) >=
  // -kSideTolerance |d| |side_normal| is on side 0 and one with dot(d, side_normal) <=
  // kSideTolerance |d| |side_normal| on side 1 (a pixel within the tolerance of the plane is on
  // both). With side_only < 0 the result holds visible_sides (no witnesses: std::invalid_argument);
  // with side_only 0 or 1 only that side's pixels mark ids and give witnesses, so `visible` is
  // that side's set. The lists (`pieces`) are those of the whole cube either way. A ray from an
  // eye that leaves a convex region through a portal point q goes on as the ray from q in the
  // same direction, whose direction points out of the region: a portal's run serves the regions
  // on both sides, each with the directions that leave it (docs/quake.md "Portals").
  Vec3 side_normal{0, 0, 0};
  int side_only = -1;
  // More planes through the eye (zero: none; with side_normal and side_only < 0): plane k (0 is
  // side_normal, k >= 1 more_side_normals[k - 1], the non-zero ones first) splits the directions
  // as side_normal does, and the result holds visible_sides[2 k + side] for each. One run then
  // serves segments that stand for the edges of several portals meeting along one line, each
  // with its own plane; the sides of plane k are those of a run split by plane k alone.
  std::array<Vec3, kMaxSidePlanes - 1> more_side_normals{};
  // Static scenes without spheres: empty (the whole cube), or one flag per tile of the cube,
  // at tile_mask_index(face, x, y, tiles) (tiles = tiles_per_side(resolution, tile size), the tile
  // size tile_size or kStaticTileSize when 0), and only the flagged tiles'
  // pixels are computed: the result is the whole run's ids seen in those pixels (pixels are
  // independent). Of another size, or in another scene: std::invalid_argument.
  std::vector<uint8_t> tile_mask;
};

// The planes a run's directions are split by: 0 without a side normal, else 1 and the leading
// non-zero more_side_normals.
int side_plane_count(const SegmentOptions& opt);

constexpr size_t kMaxSplitParts = 8;
// Pixels whose direction lies within this of a side plane (a cosine: |dot(d, n)| / (|d| |n|)) are
// on both sides, so that rounding never drops a pixel from the side it belongs to.
constexpr double kSideTolerance = 1e-9;

struct SegmentStats {
  uint64_t pair_tests = 0;     // (triangle, pixel) coverage evaluations
  uint64_t culled_pairs = 0;   // (triangle, pixel) pairs skipped by per-pixel depth culling
  uint64_t covered_pairs = 0;  // of which gave a non-empty interval
  uint64_t hidden_pairs = 0;   // of which lay behind a covered pixel's one piece (not inserted)
  uint64_t final_pieces = 0;   // pieces in all final lists
  uint64_t pixels_with_pieces = 0;
  uint64_t max_pieces_per_pixel = 0;
  uint64_t triangle_tiles = 0;         // (triangle, tile) pairs binned
  uint64_t culled_triangle_tiles = 0;  // of which skipped by depth culling
  uint64_t bvh_nodes_opened = 0;       // with a BVH: (node, tile) pairs whose children were read
  uint64_t primitives_bounded = 0;  // without a BVH: (primitive, face) pairs of the per-face pass
  double peak_tile_bytes = 0;       // largest memory held by one tile's pixel lists
  double seconds = 0;               // wall time of the call
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
    bvh_nodes_opened += o.bvh_nodes_opened;
    primitives_bounded += o.primitives_bounded;
    peak_tile_bytes = peak_tile_bytes > o.peak_tile_bytes ? peak_tile_bytes : o.peak_tile_bytes;
  }
  double pieces_per_pixel() const {
    return pixels_with_pieces ? double(final_pieces) / double(pixels_with_pieces) : 0.0;
  }
};

struct SegmentResult {
  std::vector<uint32_t> visible;          // sorted triangle ids
  std::vector<uint32_t> visible_spheres;  // sorted sphere indices (dynamic kernel)
  std::vector<Witness> witnesses;         // if requested: one per visible id, in id order
  // With options.splits: the sorted triangle ids visible from each part (visible is their union).
  std::vector<std::vector<uint32_t>> visible_parts;
  // With options.side_normal and side_only < 0: the sorted triangle ids visible at the pixels of
  // side 0 and of side 1 (visible is their union); with more_side_normals, 2 K lists, those of
  // plane k at 2 k and 2 k + 1.
  std::vector<std::vector<uint32_t>> visible_sides;
  // If requested: final list of pixel (face, x, y) at index (face * N + y) * N + x.
  std::vector<PieceList> pieces;
  // If requested, for dynamic scenes in Diagonal mode (instead of `pieces`): same indexing; ids
  // are triangle ids, and triangle_count + s for sphere s. t0, t1 are on the whole segment; each
  // depth function stays in the local parameter of its state interval [t_k, t_k+1] (evaluate it
  // at (t - t_k) / (t_k+1 - t_k), with t_k = k / (states - 1)).
  std::vector<std::vector<GeneralPiece>> general_pieces;
  SegmentStats stats;
};

// The error of the kernels for see-through objects (Object::see_through) in a scene with moving
// vertices or spheres: only static triangles can be see-through.
constexpr const char* kSeeThroughStaticOnly =
    "see-through objects are supported only in static scenes without spheres (no moving vertices, "
    "no spheres)";

// Visibility of the scene's triangles and spheres from the segment v0 -> v1. A static scene
// without spheres takes the linear path (key state `options.state`); a scene with moving vertices
// or spheres takes the dynamic kernel (dynamic_visibility.cpp; quadratic events only for what
// moves; dynamic_visibility.h) in `options.mode`. Thread-safe (reads the scene only); parallel with
// TBB.
// See-through triangles (Object::see_through; docs/visibility.md "See-through triangles")
// hide nothing: one is visible where its coverage interval at a pixel is not behind the final list
// of the opaque triangles there (a depth tie with an opaque piece, within eps_z under
// CoplanarRule::Both and exact under First, counts as visible); the lists (`pieces`) hold opaque
// triangles only, and the opaque marks are those of the scene without the see-through triangles.
// Its witness is a pixel and t where the ray from v(t) reaches it before any opaque surface (or
// at a tie); see-through triangles in front do not block it. Scenes with moving vertices or
// spheres and a see-through object: std::invalid_argument(kSeeThroughStaticOnly).
SegmentResult segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1,
                                 const SegmentOptions& options);

}  // namespace vislib
