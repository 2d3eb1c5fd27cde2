// segment_visibility.cpp: from-segment visibility for static triangles.
// Paper: "Complex VEs on All-In-One VR Headsets Through Continuous From-Segment Visibility
// Computation", §3.1, Alg. 1. Math: docs/visibility-math.md §1, §2, §5.1, §6, §7.
//
// The faces, tiles, front-to-back order and per-tile culling are the tile driver's
// (tile_driver.h, shared with the dynamic kernel). This file is the static kind: the faces each
// triangle can reach (classified once), its footprint bounds there, coverage 4 pixels at a time
// (AVX2 when the CPU has it, bit-identical to the scalar path), lower-envelope insertion of linear
// depths (triangles composited in batches of 16, row by row, so that the lists being edited stay
// in L1), and exact per-pixel culling (plane depth, and the one piece of a covered list).
#include "vislib/kernel/segment_visibility.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define VISLIB_HAVE_AVX2_PATH 1
#endif

#include "vislib/kernel/dynamic_visibility.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/kernel_support.h"
#include "vislib/kernel/static_coverage.h"
#include "vislib/kernel/tile_driver.h"

namespace vislib {

void static_edge(Vec3 a, Vec3 b, Vec3 v0, Vec3 delta, const EdgeLines* lines, EdgeRef ref, Vec3& KA,
                 Vec3& KB, double& rho) {
  // Canonical orientation: P is the lexicographically smaller world endpoint (§2.5).
  const bool forward = !lex_less(b, a);
  Vec3 P = forward ? a - v0 : b - v0;  // re-centred (docs/visibility-math.md §6)
  Vec3 Q = forward ? b - v0 : a - v0;
  Vec3 LP, LQ;  // a T-junction's edges: their run's line, the same for all (§2.5)
  if (lines && lines->line_of(ref.tri, ref.e, LP, LQ)) {
    P = LP - v0;
    Q = LQ - v0;
  }
  const Vec3 E = Q - P;
  KA = cross(E, delta);
  KB = cross(E, -P);
  rho = forward ? 1.0 : -1.0;
}

StaticTriangle prepare_static_polygon(const Vec3* c, int count, Vec3 v0, Vec3 v1,
                                      const EdgeLines* lines, const EdgeRef* refs) {
  assert(count >= 3 && count <= kMaxGroupCorners);
  StaticTriangle st;
  const Vec3 delta = v1 - v0;
  st.edges = count;
  for (int e = 0; e < count; ++e)
    static_edge(c[e], c[(e + 1) % count], v0, delta, lines, refs[e], st.KA[e], st.KB[e], st.rho[e]);
  const Vec3 r0 = c[0] - v0, r1 = c[1] - v0, r2 = c[2] - v0;
  st.n = cross(r1 - r0, r2 - r0);
  st.N0 = dot(st.n, r0);
  st.N1 = dot(st.n, delta);
  return st;
}

StaticTriangle prepare_static_triangle(const Vec3 c[3], Vec3 v0, Vec3 v1, const EdgeLines* lines,
                                       uint32_t tri) {
  const EdgeRef refs[3] = {{tri, 0}, {tri, 1}, {tri, 2}};
  return prepare_static_polygon(c, 3, v0, v1, lines, refs);
}

int side_plane_count(const SegmentOptions& opt) {
  if (opt.side_normal == Vec3{0, 0, 0}) return 0;
  int k = 1;
  while (size_t(k) < kMaxSidePlanes && !(opt.more_side_normals[size_t(k - 1)] == Vec3{0, 0, 0}))
    ++k;
  return k;
}

namespace {

// Keeps t with A t + B > 0 inside [lo, hi]; false when nothing is left.
inline bool halfline(double A, double B, double& lo, double& hi) {
  if (A > 0) {
    lo = std::max(lo, -B / A);
  } else if (A < 0) {
    hi = std::min(hi, -B / A);
  } else if (!(B > 0)) {
    return false;
  }
  return lo < hi;
}

// Keeps the side of one edge (KA, KB, rho: static_edge) that its primitive covers at pixel
// direction d, for the primitive's sign sigma = sign(d.n): an edge with A = B = 0 takes the
// symbolic perturbation d -> d + eps S + eps^2 T (§2.5). False when nothing is left.
inline bool keep_edge_side(Vec3 KA, Vec3 KB, double rho, double sigma, Vec3 d, Vec3 S, Vec3 T,
                           double& lo, double& hi) {
  double A = dot(d, KA), B = dot(d, KB);
  if (A == 0 && B == 0) {  // persistent on-edge tie
    A = dot(S, KA);
    B = dot(S, KB);
    if (A == 0 && B == 0) {
      A = dot(T, KA);
      B = dot(T, KB);
    }
  }
  const double f = sigma * rho;
  return halfline(f * A, f * B, lo, hi);
}

}  // namespace

bool static_coverage(const StaticTriangle& tri, Vec3 d, Vec3 S, Vec3 T, double near, double& lo,
                     double& hi, LinearDepth& depth) {
  const double Dn = dot(d, tri.n);
  if (Dn == 0) return false;  // ray parallel to the plane, or degenerate triangle (§2.2)
  const double sigma = Dn > 0 ? 1.0 : -1.0;
  lo = 0;
  hi = 1;
  for (int e = 0; e < tri.edges; ++e)
    if (!keep_edge_side(tri.KA[e], tri.KB[e], tri.rho[e], sigma, d, S, T, lo, hi)) return false;
  // In front of the near plane: lambda(t) > near  <=>  sigma (N0 - near Dn - N1 t) > 0.
  if (!halfline(-sigma * tri.N1, sigma * (tri.N0 - near * Dn), lo, hi)) return false;
  depth = LinearDepth{tri.N0, tri.N1, Dn};
  return true;
}

namespace {

// Bounds of LinearDepth::at(t) = (n0 - n1 t) / dn without its division: the same numerator times
// inv = 1/dn is within 3 units in the last place of the quotient (one rounding for inv, one for the
// product, one of the quotient), so widening it by 2^-50 relative (8 units) bounds at(t) from
// above or below. Non-finite products (dn near 0) fall back to the division.
// (Branch-free widening: v * (1 +- 2^-50) with the sign of v; v = +-0 stays +-0 either way.)
inline double depth_upper(const LinearDepth& z, double inv, double t) {
  const double num = z.n0 - z.n1 * t, v = num * inv;
  if (!(std::fabs(v) < INFINITY)) return z.at(t);
  return v * (1 + std::copysign(0x1p-50, v));
}
inline double depth_lower(const LinearDepth& z, double inv, double t) {
  const double num = z.n0 - z.n1 * t, v = num * inv;
  if (!(std::fabs(v) < INFINITY)) return z.at(t);
  return v * (1 - std::copysign(0x1p-50, v));
}

// True when the interval [lo, hi) with depth `depth` lies behind `q`, the one piece of a list that
// covers [0, 1], over all of [lo, hi): then it loses every comparison that insert_piece makes
// (front() at any midpoint inside it) and inserting it would leave the list as it is, so skipping
// it is exact. LinearDepth::at is monotone in t in floating point (each rounded
// operation is), so q's largest depth over [lo, hi) is at an end, as is the interval's smallest;
// depth_upper and depth_lower bound them (dividing where a product overflows). `scale` (>= 1)
// widens q's depth so that an interval within the tie tolerance of it (CoplanarRule::Both records
// such ties) is never skipped.
// (No depth envelope over t-bins is kept for lists of two or more pieces: rebuilt at the first
// test after every change, it costs more than the insertions it skips. Without it the kernel is
// 1.09x faster on the 2 m street, 1.13x on the 20 m one, even on pandora, with 0.5-1.4% more
// pairs tested. docs/performance.md.)
inline bool single_piece_hides(const Piece& q, double lo, double hi, const LinearDepth& depth,
                               double scale) {
  const double qinv = 1.0 / q.depth.dn, inv = 1.0 / depth.dn;
  const double m = std::max(depth_upper(q.depth, qinv, lo), depth_upper(q.depth, qinv, hi));
  return std::min(depth_lower(depth, inv, lo), depth_lower(depth, inv, hi)) > m * scale;
}

// An upper bound of a list's depth over all its pieces (depth_upper at each piece's ends: the
// depth is monotone on a piece).
inline double upper_depth(const PieceList& l) {
  double far = -INFINITY;
  for (const Piece& p : l) {
    const double inv = 1.0 / p.depth.dn;
    far = std::max({far, depth_upper(p.depth, inv, p.t0), depth_upper(p.depth, inv, p.t1)});
  }
  return far;
}

// True when the triangle's plane lies behind `far` along the pixel ray for every t in [0, 1]: its
// depth there is at(t) of LinearDepth{N0, N1, Dn} (as static_coverage would give), monotone in t,
// so at(0) and at(1) bound it. Exact culling of a pair whose pixel list covers [0, 1] below `far`.
inline bool plane_behind(const StaticTriangle& st, double Dn, double far) {
  if (Dn == 0) return true;  // never covers (static_coverage returns false)
  const LinearDepth z{st.N0, st.N1, Dn};
  const double inv = 1.0 / Dn;
  return std::min(depth_lower(z, inv, 0.0), depth_lower(z, inv, 1.0)) > far;
}

// ---- Coverage of one triangle at 4 consecutive pixels of a row -----------------------------
// The same operations as static_coverage, lane by lane and in the same order (no FMA, IEEE
// division, max/min with the operand order of std::max/std::min), so every lane's interval and
// depth are bit-identical to the scalar function's; lanes that hit the tie rule of §2.5 (A = B = 0
// on an edge) are redone by the scalar function. AVX2 is chosen at run time; other CPUs and
// SegmentOptions::simd = false take the scalar loop.
struct Coverage4 {
  double lo[4], hi[4], dn[4];  // (1 / dn, for the depth bounds, is divided where they need it:
                               // most pairs never do)
  bool ok[4];
};

void coverage4_scalar(const StaticTriangle& st, const FaceAxes& ax, const double* sc, double tc,
                      int lanes, double near, Coverage4& out) {
  for (int i = 0; i < lanes; ++i) {
    Vec3 d = ax.F + ax.S * sc[i] + ax.T * tc;
    LinearDepth z;
    out.ok[i] = static_coverage(st, d, ax.S, ax.T, near, out.lo[i], out.hi[i], z);
    out.dn[i] = dot(d, st.n);
  }
}

#ifdef VISLIB_HAVE_AVX2_PATH
#define VISLIB_AVX2 __attribute__((target("avx2")))
// (F + S sc) + (T tc), one component, as Vec3 arithmetic does it.
VISLIB_AVX2 inline __m256d dir_comp(double f, double sx, double tx_tc, __m256d s) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_set1_pd(f), _mm256_mul_pd(_mm256_set1_pd(sx), s)),
                       _mm256_set1_pd(tx_tc));
}
// (d.x v.x + d.y v.y) + d.z v.z, as dot() does it.
VISLIB_AVX2 inline __m256d dot4(__m256d dx, __m256d dy, __m256d dz, Vec3 v) {
  return _mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(dx, _mm256_set1_pd(v.x)), _mm256_mul_pd(dy, _mm256_set1_pd(v.y))),
      _mm256_mul_pd(dz, _mm256_set1_pd(v.z)));
}
// halfline() of every lane: keeps t with A t + B > 0 in [lo, hi]; `fail` gets the lanes with A = 0
// and B <= 0.
VISLIB_AVX2 inline void halfline4(__m256d A, __m256d B, __m256d& lo, __m256d& hi, __m256d& fail) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d pos = _mm256_cmp_pd(A, zero, _CMP_GT_OQ), neg = _mm256_cmp_pd(A, zero, _CMP_LT_OQ);
  const __m256d q = _mm256_div_pd(_mm256_sub_pd(zero, B), A);  // -B / A (the negation is exact)
  lo = _mm256_blendv_pd(lo, _mm256_max_pd(q, lo), pos);        // std::max(lo, q): q if q > lo
  hi = _mm256_blendv_pd(hi, _mm256_min_pd(q, hi), neg);        // std::min(hi, q): q if q < hi
  const __m256d flat =
      _mm256_andnot_pd(_mm256_or_pd(pos, neg), _mm256_cmp_pd(B, zero, _CMP_NGT_UQ));
  fail = _mm256_or_pd(fail, flat);
}

VISLIB_AVX2 void coverage4_avx2(const StaticTriangle& st, const FaceAxes& ax, const double* sc,
                                double tc, int lanes, double near, Coverage4& out) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), mone = _mm256_set1_pd(-1.0);
  const __m256d s = _mm256_loadu_pd(sc);
  const __m256d dx = dir_comp(ax.F.x, ax.S.x, ax.T.x * tc, s),
                dy = dir_comp(ax.F.y, ax.S.y, ax.T.y * tc, s),
                dz = dir_comp(ax.F.z, ax.S.z, ax.T.z * tc, s);
  const __m256d Dn = dot4(dx, dy, dz, st.n);
  __m256d fail = _mm256_cmp_pd(Dn, zero, _CMP_EQ_OQ);
  const __m256d sigma = _mm256_blendv_pd(mone, one, _mm256_cmp_pd(Dn, zero, _CMP_GT_OQ));
  __m256d lo = zero, hi = one, tie = zero;
  for (int e = 0; e < st.edges; ++e) {
    const __m256d A = dot4(dx, dy, dz, st.KA[e]), B = dot4(dx, dy, dz, st.KB[e]);
    tie = _mm256_or_pd(
        tie, _mm256_and_pd(_mm256_cmp_pd(A, zero, _CMP_EQ_OQ), _mm256_cmp_pd(B, zero, _CMP_EQ_OQ)));
    const __m256d f = _mm256_mul_pd(sigma, _mm256_set1_pd(st.rho[e]));
    halfline4(_mm256_mul_pd(f, A), _mm256_mul_pd(f, B), lo, hi, fail);
  }
  const __m256d nsig = _mm256_sub_pd(zero, sigma);
  halfline4(_mm256_mul_pd(nsig, _mm256_set1_pd(st.N1)),
            _mm256_mul_pd(sigma, _mm256_sub_pd(_mm256_set1_pd(st.N0),
                                               _mm256_mul_pd(_mm256_set1_pd(near), Dn))),
            lo, hi, fail);
  const __m256d good = _mm256_andnot_pd(fail, _mm256_cmp_pd(lo, hi, _CMP_LT_OQ));
  _mm256_storeu_pd(out.lo, lo);
  _mm256_storeu_pd(out.hi, hi);
  _mm256_storeu_pd(out.dn, Dn);
  const int gm = _mm256_movemask_pd(good), tm = _mm256_movemask_pd(tie);
  for (int i = 0; i < lanes; ++i) {
    if (tm >> i & 1) {  // persistent on-edge tie in this lane: the scalar rule decides
      Vec3 d = ax.F + ax.S * sc[i] + ax.T * tc;
      LinearDepth z;
      out.ok[i] = static_coverage(st, d, ax.S, ax.T, near, out.lo[i], out.hi[i], z);
    } else {
      out.ok[i] = gm >> i & 1;
    }
  }
}
#endif

bool cpu_has_avx2() {
#ifdef VISLIB_HAVE_AVX2_PATH
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

// The static triangles of one segment for the tile driver (tile_driver.h): footprint bounds on
// the faces each triangle can reach, coverage 4 pixels at a time, exact per-pixel depth culling,
// lists of linear depths.
class StaticKind {
 public:
  // A triangle of the tile set up for compositing (cover, flush).
  struct Pending {
    StaticTriangle st;
    double margin;  // of its footprint, whose hull is the batch slot's in Scratch::hulls
    int hull_size;
    uint32_t id;
    float zmin;
    int y0, y1;  // its rows in the tile
  };
  static constexpr size_t kBatch = 16;
  // The inner edges of a fan of m triangles for one segment, as for_each_triangle_part cuts at
  // them: edge 2 of triangle j < m - 1 (cut[2 j]) and edge 0 of triangle j > 0 (cut[2 j - 1]), each
  // computed by static_edge with its own edge reference; and the fan's plane normal relative to
  // v0, the sign of whose dot product with a pixel ray is the fan's side (sigma).
  static constexpr int kMaxFanCuts = 2 * (kMaxGroupCorners - 3);
  struct FanEdges {
    uint64_t segment = 0;  // the StaticKind (its serial) and primitive they belong to; 0: none
    uint32_t p = 0;
    Vec3 n;
    Vec3 KA[kMaxFanCuts], KB[kMaxFanCuts];
    double rho[kMaxFanCuts];
  };
  // Slots of the per-thread cache of fans' inner edges (Scratch::fan_edges, 376 KiB): fan p takes
  // slot p mod kFanEdgeSlots, and one that another fan took since is computed again. Computing
  // the cuts' coefficients pixel after pixel instead took lqdm1's bake 1.22 times the CPU.
  static constexpr size_t kFanEdgeSlots = 1024;
  struct Scratch {
    std::vector<PieceList> lists;
    std::vector<double> far;  // per pixel: an upper bound of its list's depth (inf unless the list
                              // covers [0, 1])
    std::vector<std::vector<TieRecord>> ties;                   // per pixel (CoplanarRule::Both)
    std::vector<Pending> batch = std::vector<Pending>(kBatch);  // triangles set up, not composited
    std::vector<Vec2> hulls = std::vector<Vec2>(kBatch * kMaxFootprintPoints);  // a slot each
    size_t batch_size = 0;
    // See-through triangles of the tile, set up, kept until its opaque lists are final
    // (finish_tile); their hulls, a slot each.
    std::vector<Pending> see_through;
    std::vector<Vec2> see_through_hulls;
    // The inner edges of the fans this thread cut last (fan_edges_of): a direct-mapped cache of
    // kFanEdgeSlots, empty until a fan is cut.
    std::vector<FanEdges> fan_edges;
  };

  StaticKind(const Scene& scene, Vec3 v0, Vec3 v1, const SegmentOptions& opt,
             std::vector<PieceList>* pieces)
      : scene_(scene), v0_(v0), v1_(v1), opt_(opt), pieces_(pieces) {
    const int N = opt.resolution;
    keep_ties_ = opt.coplanar == CoplanarRule::Both;
    // Depth culling stays exact with ties: a triangle tied with the front lies within eps_z of
    // it, so only triangles beyond far * (1 + eps_z) are skipped (2 eps_z covers the rounding).
    far_scale_ = keep_ties_ ? 1 + 2 * opt.eps_z : 1.0;
    if (!opt.splits.empty()) {
      part_bounds_.push_back(0.0);
      part_bounds_.insert(part_bounds_.end(), opt.splits.begin(), opt.splits.end());
      part_bounds_.push_back(1.0);
    }
    // Pixel-centre coordinates (pixel_center), padded so that 4 lanes can always be loaded.
    pixel_centers_.assign(size_t(N) + 4, 0.0);
    for (int i = 0; i < N; ++i) pixel_centers_[size_t(i)] = pixel_center(i, N);
#ifdef VISLIB_HAVE_AVX2_PATH
    coverage4_ = opt.simd && cpu_has_avx2() ? coverage4_avx2 : coverage4_scalar;
#else
    coverage4_ = coverage4_scalar;
#endif
    // The faces each triangle can reach; with a BVH, only the triangles its
    // walk reaches get bounds, so nothing is classified up front.
    if (opt.edge_lines) {
      lines_ = opt.edge_lines;
    } else {
      own_lines_ = build_edge_lines(scene, opt.state);
      lines_ = &own_lines_;
    }
    // The primitives: the tree's (triangle_groups.h), or without a tree the fans when asked for.
    if (opt.bvh && !opt.bvh->groups.first.empty()) groups_ = &opt.bvh->groups;
    if (!opt.bvh && opt.fans) {
      own_groups_ = build_triangle_groups(scene, opt.state);
      if (!own_groups_.first.empty()) groups_ = &own_groups_;
    }
    if (!opt.bvh)
      faces_ = classify_faces(count(), opt,
                              [this](size_t p, Vec3* rel) { return relative_corners(p, rel); });
    for (int f = 0; f < kCubeFaces; ++f) face_axes_[size_t(f)] = face_axes(f, opt.orientation);
    has_see_through_ = scene.has_see_through();
    if (!(opt.side_normal == Vec3{0, 0, 0})) {
      sides_ = true;
      planes_ = side_plane_count(opt);
      all_sides_ = opt.side_only < 0 ? uint8_t((1u << (2 * planes_)) - 1) : 1;
      for (int k = 0; k < planes_; ++k) {
        const Vec3 n = k == 0 ? opt.side_normal : opt.more_side_normals[size_t(k - 1)];
        for (int f = 0; f < kCubeFaces; ++f) {
          const FaceAxes& a = face_axes_[size_t(f)];
          side_dots_[size_t(k)][size_t(f)] = {dot(a.F, n), dot(a.S, n), dot(a.T, n)};
        }
        const double tol = kSideTolerance * length(n);  // per unit of |d|
        side_tol2_[size_t(k)] = tol * tol;
      }
    }
  }

  static constexpr bool kHasBvh = true;
  const TriangleBvh* bvh() const {
    return opt_.bvh;
  }
  bool node_bounds(uint32_t node, const FaceAxes& axes, int* b, double& zmin) const {
    const TriangleBvh::Node& n = opt_.bvh->nodes[node];
    return box_footprint_bounds(n.lo, n.hi, v0_, v1_, axes, opt_.near, opt_.resolution, b[0], b[1],
                                b[2], b[3], zmin);
  }

  // The primitives: the groups of the tree's fans, or the triangles.
  size_t count() const {
    return groups_ ? groups_->count(scene_.triangle_count()) : scene_.triangle_count();
  }

  Scratch make_scratch(int ts) const {
    const size_t n = size_t(ts) * size_t(ts);
    Scratch s;
    s.lists.resize(n);
    s.far.resize(n);
    s.ties.resize(n);
    return s;
  }

  // The pixel rectangle of the footprint (footprint_bounds: the hull's rectangle without the
  // hull) and the nearest depth, on the faces the triangle can reach.
  bool bounds(size_t t, int face, const FaceAxes& axes, int* b, double& zmin) const {
    if (!faces_.empty() && !(faces_[t] >> face & 1)) return false;
    Vec3 rel[2 * kMaxGroupCorners];
    const int n = relative_corners(t, rel);
    return footprint_bounds(rel, n, axes, opt_.near, opt_.resolution, b[0], b[1], b[2], b[3], zmin);
  }

  // A triangle of the tile, set up and put in the batch; the batch is composited row by row
  // when full (and at the end of the tile: flush). Row by row, the lists being edited are one
  // row's (32 pixels, a few KB) instead of the whole tile's (hundreds of KB, beyond L1), and each
  // pixel still gets its insertions in the tile's order (the batch's order within a row).
  // Per-pixel culling reads the pixel's state when the pair is composited, and the tile driver
  // flushes the batch before it recomputes its bounds, so every culling is as strong as without
  // batches. Measured: 1.02-1.06x on the kernel suite; the search in insert_piece
  // no longer waits for memory, but most of that time moved elsewhere (docs/performance.md).
  // See-through triangles (Object::see_through) take another path: they are set up here but
  // composited into nothing; finish_tile tests them against the tile's final opaque lists. Scenes
  // without them pay one predictable branch per (triangle, tile).
  void cover(Scratch& sc, const TileItem& item, const int* box, const TileRect& rect,
             const FaceAxes& axes, SegmentStats& stats) const {
    if (has_see_through_ && scene_.triangle_see_through(first_triangle(item.id))) {
      sc.see_through.emplace_back();
      sc.see_through_hulls.resize(sc.see_through.size() * kMaxFootprintPoints);
      if (!set_up(sc.see_through.back(),
                  &sc.see_through_hulls[sc.see_through_hulls.size() - kMaxFootprintPoints], item,
                  box, rect, axes))
        sc.see_through.pop_back();
      return;
    }
    if (!set_up(sc.batch[sc.batch_size], &sc.hulls[sc.batch_size * kMaxFootprintPoints], item, box,
                rect, axes))
      return;
    if (++sc.batch_size == kBatch) flush(sc, rect, axes, stats);
  }

  void begin_tile(Scratch& sc) const {  // the driver resets the per-pixel state
    sc.see_through.clear();
  }
  size_t held_bytes(const Scratch&) const {  // (the fan edge cache is a fixed size, not a tile's)
    return 0;
  }

  void flush(Scratch& sc, const TileRect& rect, const FaceAxes& axes, SegmentStats& stats) const {
    if (sc.batch_size == 0) return;
    int ylo = rect.y1, yhi = rect.y0;
    for (size_t i = 0; i < sc.batch_size; ++i) {
      ylo = std::min(ylo, sc.batch[i].y0);
      yhi = std::max(yhi, sc.batch[i].y1);
    }
    for (int y = ylo; y <= yhi; ++y)
      for (size_t i = 0; i < sc.batch_size; ++i) {
        const Pending& b = sc.batch[i];
        if (y >= b.y0 && y <= b.y1)
          cover_row(sc, b, &sc.hulls[i * kMaxFootprintPoints], y, rect, axes, stats);
      }
    sc.batch_size = 0;
  }

  // The see-through triangles of the tile against its final opaque lists (the driver calls this
  // after the last flush): at each pixel of its footprint, the stretches of its coverage interval
  // that no opaque piece hides (for_each_see_through_stretch) mark it, with a witness at the
  // middle of the longest. Nothing is inserted, so the lists, and the opaque marks, are those of
  // the scene without the see-through triangles. Per-pixel culling as for opaque triangles
  // (`far` includes the tie margin).
  void finish_tile(Scratch& sc, int face, const TileRect& rect, const FaceAxes& axes,
                   FoundMarks& found, SegmentStats& stats) const {
    const bool witnesses = !found.witness_len.empty();
    for (size_t i = 0; i < sc.see_through.size(); ++i) {
      const Pending& b = sc.see_through[i];
      const uint32_t tri = first_triangle(b.id);  // (a see-through group is one triangle)
      if (!witnesses && part_bounds_.empty() && found.seen(tri) == all_sides_)
        continue;  // nothing to add
      const Vec2* hull = &sc.see_through_hulls[i * kMaxFootprintPoints];
      const StaticTriangle& st = b.st;
      for (int y = b.y0; y <= b.y1; ++y) {
        int x0, x1;
        if (!footprint_row_span(hull, b.hull_size, b.margin, opt_.resolution, y, x0, x1)) continue;
        x0 = std::max(x0, rect.x0);
        x1 = std::min(x1, rect.x1);
        const double tc = pixel_centers_[size_t(y)];
        for (int x = x0; x <= x1; ++x) {
          const uint8_t sides = side_mask(face, x, y);
          if (sides == 0) continue;
          const size_t k = rect.index(x, y);
          const Vec3 d = axes.F + axes.S * pixel_centers_[size_t(x)] + axes.T * tc;
          const double far = sc.far[k];
          if (opt_.depth_culling &&
              (double(b.zmin) > far || (far < INFINITY && plane_behind(st, dot(d, st.n), far)))) {
            ++stats.culled_pairs;
            continue;
          }
          ++stats.pair_tests;
          double lo, hi;
          LinearDepth depth;
          if (!static_coverage(st, d, axes.S, axes.T, opt_.near, lo, hi, depth)) continue;
          ++stats.covered_pairs;
          for_each_see_through_stretch(sc.lists[k], Piece{lo, hi, b.id, depth}, keep_ties_,
                                       opt_.eps_z, [&](double t0, double t1) {
                                         if (!part_bounds_.empty()) {
                                           mark_parts(found, part_bounds_, opt_.eps_len, tri, t0,
                                                      t1);
                                           return;
                                         }
                                         mark(found, tri, sides, face, x, y, t0, t1);
                                       });
        }
      }
    }
  }

 private:
  // Sets up triangle `item` for compositing in the tile (its hull written to `hull`); false when it
  // covers nothing there.
  bool set_up(Pending& b, Vec2* hull, const TileItem& item, const int* box, const TileRect& rect,
              const FaceAxes& axes) const {
    Vec3 c[kMaxGroupCorners];
    EdgeRef refs[kMaxGroupCorners];
    const int n = primitive_corners(item.id, c, refs);
    b.st = prepare_static_polygon(c, n, v0_, v1_, lines_, refs);
    if (b.st.n == Vec3{0, 0, 0}) return false;  // degenerate: never covers (H5)
    b.y0 = std::max(rect.y0, box[2]);
    b.y1 = std::min(rect.y1, box[3]);
    if (b.y0 > b.y1) return false;
    Vec3 rel[2 * kMaxGroupCorners];
    for (int i = 0; i < n; ++i) {
      rel[i] = c[i] - v0_;
      rel[n + i] = c[i] - v1_;
    }
    b.hull_size = compute_footprint_hull(rel, 2 * n, axes, opt_.near, hull, b.margin);
    if (b.hull_size == 0) return false;  // nothing in front of the near plane on this face
    b.id = item.id;
    b.zmin = item.zmin;
    return true;
  }

  // The pairs of one batched triangle on row y of the tile.
  void cover_row(Scratch& sc, const Pending& b, const Vec2* hull, int y, const TileRect& rect,
                 const FaceAxes& axes, SegmentStats& stats) const {
    const int N = opt_.resolution;
    const double tz = double(b.zmin);
    const StaticTriangle& st = b.st;
    int x0, x1;
    if (!footprint_row_span(hull, b.hull_size, b.margin, N, y, x0, x1)) return;
    x0 = std::max(x0, rect.x0);
    x1 = std::min(x1, rect.x1);
    const double tc = pixel_centers_[size_t(y)];
    for (int xb = x0; xb <= x1; xb += 4) {
      const int lanes = std::min(4, x1 - xb + 1);
      const size_t kb = rect.index(xb, y);
      bool any = false;
      for (int i = 0; i < lanes; ++i) any |= !(opt_.depth_culling && tz > sc.far[kb + i]);
      if (!any) {
        stats.culled_pairs += uint64_t(lanes);
        continue;
      }
      Coverage4 cov;
      coverage4_(st, axes, &pixel_centers_[size_t(xb)], tc, lanes, opt_.near, cov);
      // Deep lists rarely stay in the cache: ask for the line where insert_piece's search starts
      // in each of the (up to) four lists at once, so that their misses overlap.
      for (int i = 0; i < lanes; ++i) {
        const PieceList& l = sc.lists[kb + size_t(i)];
        if (cov.ok[i] && l.size() > 16) __builtin_prefetch(&l[detail::guess_index(l, cov.lo[i])]);
      }
      for (int i = 0; i < lanes; ++i) {
        const size_t k = kb + size_t(i);
        if (opt_.depth_culling &&
            (tz > sc.far[k] || (sc.far[k] < INFINITY && plane_behind(st, cov.dn[i], sc.far[k])))) {
          ++stats.culled_pairs;
          continue;
        }
        ++stats.pair_tests;
        if (!cov.ok[i]) continue;
        ++stats.covered_pairs;
        const double lo = cov.lo[i], hi = cov.hi[i];
        const LinearDepth depth{st.N0, st.N1, cov.dn[i]};
        PieceList& l = sc.lists[k];
        // A covered pixel whose list is one piece tests the interval against it (exact; a
        // list of more pieces leaves the test to insert_piece's read-only pass).
        if (opt_.depth_culling && sc.far[k] < INFINITY && l.size() == 1 &&
            single_piece_hides(l[0], lo, hi, depth, far_scale_)) {
          ++stats.hidden_pairs;
          continue;
        }
        TieRule rule{opt_.eps_z, keep_ties_ ? &sc.ties[k] : nullptr};
        if (insert_piece(l, Piece{lo, hi, b.id, depth}, rule) && opt_.depth_culling) {
          // The list only got nearer, so a stale far is still a bound, only a looser one; a
          // list that becomes one piece gets its depth at its ends.
          if (sc.far[k] < INFINITY ? l.size() == 1 : covers_segment(l))
            sc.far[k] = upper_depth(l) * far_scale_;
        }
      }
    }
  }

 public:
  void finish_pixel(Scratch& sc, size_t k, int face, int x, int y, FoundMarks& found) const {
    const PieceList& l = sc.lists[k];
    const int N = opt_.resolution;
    if (pieces_) store_pieces(sc, l, face, x, y, (*pieces_)[(size_t(face) * N + y) * N + x]);
    if (!part_bounds_.empty()) {  // a split segment: marks per part, no witnesses
      for_each_visible(l, sc.ties[k], [&](uint32_t p, double t0, double t1) {
        for_each_triangle_part(sc, p, face, x, y, t0, t1, [&](uint32_t id, double a, double b) {
          mark_parts(found, part_bounds_, opt_.eps_len, id, a, b);
        });
      });
      return;
    }
    const uint8_t sides = side_mask(face, x, y);
    if (sides == 0) return;  // a pixel of the side not asked for
    const bool witnesses = !found.witness_len.empty();
    // Remembered per fan (FoundMarks::group_note): a fan is met again in most pixels of a run.
    auto settled = [&](uint32_t p) {
      if (witnesses) return false;
      if ((found.group_note(p) & sides) == sides) return true;
      for (uint32_t t = first_triangle(p), e = end_triangle(p); t < e; ++t)
        if ((found.seen(t) & sides) != sides) return false;
      found.add_group_note(p, sides);
      return true;
    };
    for_each_visible(
        l, sc.ties[k],
        [&](uint32_t p, double t0, double t1) {
          // A fan whose triangles are all marked already gains nothing from its parts: most
          // pieces of a run, once their triangles are found.
          if (groups_ && settled(p)) return;
          for_each_triangle_part(sc, p, face, x, y, t0, t1, [&](uint32_t id, double a, double b) {
            mark(found, id, sides, face, x, y, a, b);
          });
        },
        settled);
  }

 private:
  // Triangle `tri` seen on `sides` over [t0, t1) at pixel (x, y) of `face`, when the stretch is
  // longer than eps_len: its mark, and with witnesses the stretch's middle as a candidate.
  void mark(FoundMarks& found, uint32_t tri, uint8_t sides, int face, int x, int y, double t0,
            double t1) const {
    const double len = t1 - t0;
    if (!(len > opt_.eps_len)) return;
    if (found.witness_len.empty()) {  // the mark alone (no witness to build and compare)
      found.add(tri, sides);
      return;
    }
    Witness w;
    w.tri = tri;
    w.face = face;
    w.x = x;
    w.y = y;
    w.t = 0.5 * (t0 + t1);
    found.mark(tri, len, w);
  }

  // The final list of a pixel as SegmentResult::pieces holds it: triangle ids (a fan's pieces
  // cut into its triangles' parts, with the fan's depth).
  void store_pieces(Scratch& sc, const PieceList& l, int face, int x, int y, PieceList& out) const {
    if (!groups_) {
      out = l;
      return;
    }
    out.clear();
    for (const Piece& q : l) {
      const size_t first = out.size();
      for_each_triangle_part(sc, q.id, face, x, y, q.t0, q.t1,
                             [&](uint32_t id, double a, double b) {
                               out.push_back(Piece{a, b, id, q.depth});
                             });
      // (in triangle order, which runs either way along t)
      std::sort(out.begin() + long(first), out.end(),
                [](const Piece& u, const Piece& v) { return u.t0 < v.t0; });
    }
  }

  // The sides (SegmentOptions::side_normal) pixel (x, y) of `face` counts for, as the mark's
  // bits: 1 (side 0), 2 (side 1) or 3 (both, on the plane) when the sides are split; 1 when it
  // is on the side asked for (side_only), 0 when not; 1 without sides.
  // Called for every pixel with pieces, so the plane's terms are taken per face (side_dots_)
  // and |dn| <= tol is tested squared, without a root.
  // With more planes (SegmentOptions::more_side_normals) plane k's bits are shifted by 2 k.
  uint8_t side_mask(int face, int x, int y) const {
    if (!sides_) return 1;
    const double sc = pixel_centers_[size_t(x)], tc = pixel_centers_[size_t(y)];
    const double d2 = 1 + sc * sc + tc * tc;  // |d|^2
    uint8_t mask = 0;
    for (int k = 0; k < planes_; ++k) {
      const std::array<double, 3>& n = side_dots_[size_t(k)][size_t(face)];
      const double dn = n[0] + n[1] * sc + n[2] * tc;  // dot(d, normal), d = F + S sc + T tc
      const double tol2 = side_tol2_[size_t(k)] * d2;  // (tolerance |d|)^2
      mask |= uint8_t((dn * dn <= tol2 ? 3 : dn > 0 ? 1 : 2) << (2 * k));
    }
    if (opt_.side_only < 0) return mask;
    return uint8_t(mask >> opt_.side_only & 1);
  }

  // Primitive p's corners minus v0, then minus v1 (room for 2 kMaxGroupCorners); their count.
  int relative_corners(size_t p, Vec3* rel) const {
    Vec3 c[kMaxGroupCorners];
    EdgeRef refs[kMaxGroupCorners];
    const int n = primitive_corners(uint32_t(p), c, refs);
    for (int i = 0; i < n; ++i) {
      rel[i] = c[i] - v0_;
      rel[n + i] = c[i] - v1_;
    }
    return 2 * n;
  }

  // Primitive p's triangles: first_triangle(p) ... end_triangle(p) - 1.
  uint32_t first_triangle(uint32_t p) const {
    return groups_ ? groups_->begin(p) : p;
  }
  uint32_t end_triangle(uint32_t p) const {
    return groups_ ? groups_->end(p) : p + 1;
  }

  // Primitive p's corners (room for kMaxGroupCorners) and the scene's edge of each of its edges
  // (corner i to i + 1): a triangle's three, or a fan's polygon (triangle_groups.h); their count.
  int primitive_corners(uint32_t p, Vec3* c, EdgeRef* refs) const {
    const uint32_t b = first_triangle(p), e = end_triangle(p);
    const int n = group_corners(scene_, opt_.state, b, e, c);
    // Edge 0 (a b) of the first triangle, edge 1 (its second and third corners) of each, edge 2
    // (back to a) of the last.
    refs[0] = {b, 0};
    for (uint32_t t = b; t < e; ++t) refs[1 + (t - b)] = {t, 1};
    refs[n - 1] = {e - 1, 2};
    return n;
  }

 public:
  // Calls f(tri, a, b) for each triangle of primitive p and its part [a, b) (not empty) of the
  // stretch [t0, t1) of p at pixel (x, y) of `face`: the stretch itself for a triangle; for a
  // fan, the stretch cut at its inner edges, each cut computed as the triangle kernel computes
  // that edge's (static_edge, the §2.5 tie rule), so that the parts are the pieces the triangles
  // would have had (§2.6).
  template <class F>
  void for_each_triangle_part(Scratch& sc, uint32_t p, int face, int x, int y, double t0, double t1,
                              F f) const {
    const uint32_t first = first_triangle(p), m = end_triangle(p) - first;
    if (m == 1) {
      f(first, t0, t1);
      return;
    }
    const FanEdges& fe = fan_edges_of(sc, p);
    const FaceAxes& ax = face_axes_[size_t(face)];
    const Vec3 d = ax.F + ax.S * pixel_centers_[size_t(x)] + ax.T * pixel_centers_[size_t(y)];
    const double sigma = dot(d, fe.n) > 0 ? 1.0 : -1.0;
    auto keep = [&](int cut, double& lo, double& hi) {
      return keep_edge_side(fe.KA[cut], fe.KB[cut], fe.rho[cut], sigma, d, ax.S, ax.T, lo, hi);
    };
    for (uint32_t j = 0; j < m; ++j) {  // triangle first + j
      double lo = t0, hi = t1;
      if (j > 0 && !keep(int(2 * j) - 1, lo, hi)) continue;
      if (j + 1 < m && !keep(int(2 * j), lo, hi)) continue;
      if (lo < hi) f(first + j, lo, hi);
    }
  }

 private:
  // The inner edges of fan p (FanEdges) for this segment, from this thread's cache.
  const FanEdges& fan_edges_of(Scratch& sc, uint32_t p) const {
    if (sc.fan_edges.empty()) sc.fan_edges.resize(kFanEdgeSlots);
    FanEdges& fe = sc.fan_edges[p % kFanEdgeSlots];
    if (fe.segment == serial_ && fe.p == p) return fe;
    Vec3 c[kMaxGroupCorners];
    EdgeRef refs[kMaxGroupCorners];
    const int n = primitive_corners(p, c, refs);
    const Vec3 delta = v1_ - v0_;
    const Vec3 r0 = c[0] - v0_;
    fe.n = cross((c[1] - v0_) - r0, (c[2] - v0_) - r0);
    const uint32_t first = first_triangle(p);
    for (int j = 0; j < n - 2; ++j) {  // triangle first + j: c[0], c[j + 1], c[j + 2]
      const uint32_t tri = first + uint32_t(j);
      if (j > 0) {
        const int cut = 2 * j - 1;
        static_edge(c[0], c[j + 1], v0_, delta, lines_, EdgeRef{tri, 0}, fe.KA[cut], fe.KB[cut],
                    fe.rho[cut]);
      }
      if (j < n - 3) {
        const int cut = 2 * j;
        static_edge(c[j + 2], c[0], v0_, delta, lines_, EdgeRef{tri, 2}, fe.KA[cut], fe.KB[cut],
                    fe.rho[cut]);
      }
    }
    fe.segment = serial_;
    fe.p = p;
    return fe;
  }

  const Scene& scene_;
  Vec3 v0_, v1_;
  const uint64_t serial_ = next_serial();  // tells this segment's cached fan edges apart
  const SegmentOptions& opt_;
  std::vector<PieceList>* pieces_;
  EdgeLines own_lines_;  // built for this call when the caller passes none
  const EdgeLines* lines_ = nullptr;
  std::vector<double> part_bounds_;  // 0, the splits, 1 (empty: not split)
  bool sides_ = false;               // side_normal given
  int planes_ = 0;                   // with sides: side_plane_count
  uint8_t all_sides_ = 1;            // the mark of an id seen on every side that counts
  // With sides, for each plane k: dot(F, normal), dot(S, ...), dot(T, ...) of each face's axes,
  // and (kSideTolerance |normal|)^2 (side_mask).
  std::array<std::array<std::array<double, 3>, kCubeFaces>, kMaxSidePlanes> side_dots_{};
  std::array<double, kMaxSidePlanes> side_tol2_{};
  std::array<FaceAxes, kCubeFaces> face_axes_{};  // world axes of each face
  TriangleGroups own_groups_;                     // built for this call (no tree, fans)
  const TriangleGroups* groups_ = nullptr;        // the primitives' fans; null: triangles
  bool keep_ties_ = false;
  bool has_see_through_ = false;
  double far_scale_ = 1.0;
  std::vector<double> pixel_centers_;
  decltype(&coverage4_scalar) coverage4_ = nullptr;
  std::vector<uint8_t> faces_;
};

}  // namespace

SegmentResult segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1, const SegmentOptions& opt) {
  assert(opt.resolution >= 1 && opt.near > 0 && opt.tile_size >= 0);
  if (!opt.splits.empty()) {
    bool ok = opt.splits.size() < kMaxSplitParts && opt.splits.front() > 0 && opt.splits.back() < 1;
    for (size_t i = 1; i < opt.splits.size(); ++i) ok = ok && opt.splits[i - 1] < opt.splits[i];
    if (!ok)
      throw std::invalid_argument(
          "segment split points must increase strictly inside (0, 1), at most " +
          std::to_string(kMaxSplitParts - 1));
    if (scene.sphere_count() > 0 || scene.is_dynamic())
      throw std::invalid_argument("a segment can be split only in a static scene without spheres");
  }
  if (!(opt.side_normal == Vec3{0, 0, 0})) {
    if (!opt.splits.empty() || scene.sphere_count() > 0 || scene.is_dynamic())
      throw std::invalid_argument(
          "directions can be split by a plane only in a static scene without spheres, on a "
          "segment that is not split");
    if (opt.side_only < -1 || opt.side_only > 1)
      throw std::invalid_argument("side_only must be -1 (both sides), 0 or 1");
    if (opt.side_only < 0 && opt.want_witnesses)
      throw std::invalid_argument("witnesses need one side (side_only 0 or 1), not both");
  }
  const int planes = side_plane_count(opt);
  for (size_t k = size_t(std::max(planes, 1)); k < kMaxSidePlanes; ++k)
    if (!(opt.more_side_normals[k - 1] == Vec3{0, 0, 0}))
      throw std::invalid_argument("more side planes come first, after a side normal");
  if (planes > 1 && opt.side_only >= 0)
    throw std::invalid_argument("more side planes need both sides (side_only -1)");
  if (!opt.tile_mask.empty()) {
    if (scene.sphere_count() > 0 || scene.is_dynamic())
      throw std::invalid_argument("a tile mask applies only to a static scene without spheres");
    const size_t tiles =
        size_t(tiles_per_side(opt.resolution, opt.tile_size ? opt.tile_size : kStaticTileSize));
    if (opt.tile_mask.size() != size_t(kCubeFaces) * tiles * tiles)
      throw std::invalid_argument("a tile mask needs one flag per tile of the cube (" +
                                  std::to_string(size_t(kCubeFaces) * tiles * tiles) + "), not " +
                                  std::to_string(opt.tile_mask.size()));
  }
  if (scene.sphere_count() > 0 || scene.is_dynamic()) {
    if (scene.has_see_through()) throw std::invalid_argument(kSeeThroughStaticOnly);
    return dynamic_segment_visibility(scene, v0, v1, opt);  // resolves tile_size 0 itself
  }
  if (opt.tile_size == 0) {  // the kernel's choice
    SegmentOptions o = opt;
    o.tile_size = kStaticTileSize;
    return segment_visibility(scene, v0, v1, o);
  }
  if (opt.bvh && !opt.bvh->matches(scene, opt.state))
    throw std::invalid_argument(
        "the BVH given to segment_visibility was built for another scene or key state");
  if (opt.edge_lines && !opt.edge_lines->matches(scene, opt.state))
    throw std::invalid_argument(
        "the edge lines given to segment_visibility were built for another scene or key state");
  auto start = std::chrono::steady_clock::now();
  const int N = opt.resolution;
  const int tiles_x = tiles_per_side(N, opt.tile_size);
  const size_t ntri = scene.triangle_count();

  SegmentResult result;
  if (opt.want_pieces) result.pieces.resize(size_t(6) * N * N);
  std::vector<SegmentStats> tile_stats(size_t(6) * tiles_x * tiles_x);
  tbb::enumerable_thread_specific<FoundMarks> found_by_thread(
      [&] { return FoundMarks(ntri, opt.want_witnesses); });
  StaticKind kind(scene, v0, v1, opt, opt.want_pieces ? &result.pieces : nullptr);
  run_tiles(kind, opt, found_by_thread, tile_stats);

  // Reduce: statistics in tile order; marks and witnesses over threads by a total order.
  for (const SegmentStats& ts : tile_stats) result.stats.add(ts);
  std::vector<uint8_t> seen;
  std::vector<Witness> best;
  reduce_found(found_by_thread, ntri, opt.want_witnesses, seen, best);
  for (size_t t = 0; t < ntri; ++t)
    if (seen[t]) {
      result.visible.push_back(uint32_t(t));
      if (opt.want_witnesses && opt.splits.empty()) result.witnesses.push_back(best[t]);
    }
  if (!(opt.side_normal == Vec3{0, 0, 0}) && opt.side_only < 0) {
    result.visible_sides.resize(2 * size_t(side_plane_count(opt)));
    for (uint32_t t : result.visible)
      for (size_t i = 0; i < result.visible_sides.size(); ++i)
        if (seen[t] >> i & 1) result.visible_sides[i].push_back(t);
  }
  if (!opt.splits.empty()) {
    result.visible_parts.resize(opt.splits.size() + 1);
    for (uint32_t t : result.visible)
      for (size_t i = 0; i < result.visible_parts.size(); ++i)
        if (seen[t] >> i & 1) result.visible_parts[i].push_back(t);
  }
  result.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vislib
