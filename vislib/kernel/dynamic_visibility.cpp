// dynamic_visibility.cpp: from-segment visibility of moving triangles and spheres.
// Paper: §3.2 (moving triangles) and §3.3 (spheres) of "Complex VEs on All-In-One VR Headsets
// Through Continuous From-Segment Visibility Computation". Math: docs/
// visibility-math.md §3 (edge quadratics, rational depth, two-branch coverage), §4 (spheres, with
// the in-front and eye-inside conditions), §5 (footprints), §3.4 (crossings), E10 (modes).
//
// A run is a piece of space-time where everything moves linearly in a local parameter s in [0,1]:
// the eye from e0 to e1, every vertex from key state k0 to k1, every sphere centre likewise. The
// dynamic scene's answer is the union of runs (docs/visibility.md):
//   Diagonal: eye parameter t and animation time tau advance together; one run per state interval.
//   Decoupled: the diagonal runs, plus the eye fixed at v0 and at v1 while the scene animates
//     (one run per state interval each), plus the scene frozen at each key state while the eye
//     moves v0 -> v1.
// Inside a run, primitives that do not move use the linear events of the static kernel; only
// moving triangles use quadratic edge events and the cubic in-front condition.
#include "vislib/kernel/dynamic_visibility.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "vislib/base/polynomial.h"
#include "vislib/base/tolerances.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/kernel_support.h"
#include "vislib/kernel/static_coverage.h"
#include "vislib/kernel/tile_driver.h"

namespace vislib {

// ---- Depth functions ----------------------------------------------------------------------

double GeneralDepth::at(double t) const {
  if (kind == Rational) return poly_eval(c, 3, t) / poly_eval(c + 4, 2, t);
  double h = c[0] + c[1] * t;
  double m = poly_eval(c + 2, 2, t);
  double g = std::max(0.0, poly_eval(c + 5, 2, t));
  double sq = std::sqrt(g), dd = c[8];
  if (kind == SphereFar) return (-h + sq) / dd;
  return h < 0 ? m / (-h + sq) : (-h - sq) / dd;  // stable form of the near root (§4)
}

bool same_depth(const GeneralDepth& a, const GeneralDepth& b) {
  if (a.kind != b.kind) return false;
  for (int k = 0; k < 16; ++k)
    if (a.c[k] != b.c[k]) return false;
  return true;
}

// The crossings are the roots of a polynomial of degree at most 6 (5 for two triangles, 4 for two
// spheres, 6 for a sphere and a triangle), and poly_roots_in writes at most deg roots: `out`
// (kMaxCrossings slots, interval_list.h) holds them all, none is ever dropped.
static_assert(kMaxCrossings >= 6, "depth_crossings writes up to 6 crossings");

int depth_crossings(const GeneralDepth& i, const GeneralDepth& j, double lo, double hi,
                    double* out) {
  if (i.kind == GeneralDepth::Rational && j.kind == GeneralDepth::Rational) {
    // sign(lambda_i - lambda_j) = sign(P) sign(D_i D_j), P = N_i D_j - N_j D_i (deg <= 5).
    double P[6] = {};
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 3; ++b) P[a + b] += i.c[a] * j.c[4 + b] - j.c[a] * i.c[4 + b];
    double scale = 0;
    for (double p : P) scale = std::max(scale, std::fabs(p));
    if (scale == 0) return 0;
    for (double& p : P) p /= scale;
    return poly_roots_in(P, 5, lo, hi, out);  // at most 5 <= kMaxCrossings roots
  }
  if (i.kind != GeneralDepth::Rational && j.kind != GeneralDepth::Rational) {
    // Two spheres that stay disjoint over the run keep their depth order (§4): no crossing.
    // Centre difference o_i - o_j = w_j - w_i = a + t b; its minimum length over [0,1].
    Vec3 a{j.c[9] - i.c[9], j.c[10] - i.c[10], j.c[11] - i.c[11]};
    Vec3 b{j.c[12] - i.c[12], j.c[13] - i.c[13], j.c[14] - i.c[14]};
    double bb = dot(b, b), tm = bb > 0 ? std::clamp(-dot(a, b) / bb, 0.0, 1.0) : 0.0;
    Vec3 m = a + b * tm;
    double rr = i.c[15] + j.c[15];
    if (dot(m, m) > rr * rr * (1 + kDisjointSpheresSlack)) return 0;
  }
  // A sphere is involved. At a crossing the ray's point at the common depth lies on both
  // surfaces, so the crossing times are among the roots of a polynomial (exact, no sampling):
  //   sphere-sphere:   Q = den^2 m_i + 2 den num h_i + num^2 |d|^2   (degree 4), with
  //                    den = 2 (h_i - h_j), num = m_j - m_i (lambda = num / den on the radical
  //                    plane);
  //   sphere-triangle: Q = D^2 m + 2 N D h + N^2 |d|^2               (degree 6), lambda = N / D.
  // Extra roots (e.g. where the far root meets) only add cut points; each sub-piece's winner is
  // decided at its midpoint.
  double Q[7] = {};
  auto mul = [](const double* a, int da, const double* b, int db, double* product) {
    for (int x = 0; x <= da + db; ++x) product[x] = 0;
    for (int x = 0; x <= da; ++x)
      for (int y = 0; y <= db; ++y) product[x + y] += a[x] * b[y];
  };
  int deg;
  if (i.kind != GeneralDepth::Rational && j.kind != GeneralDepth::Rational) {
    double den[2] = {2 * (i.c[0] - j.c[0]), 2 * (i.c[1] - j.c[1])};
    double num[3] = {j.c[2] - i.c[2], j.c[3] - i.c[3], j.c[4] - i.c[4]};
    double hi_[2] = {i.c[0], i.c[1]}, mi[3] = {i.c[2], i.c[3], i.c[4]};
    double den2[3], a[5], dn[4], b[5], nn[5];
    mul(den, 1, den, 1, den2);
    mul(den2, 2, mi, 2, a);
    mul(den, 1, num, 2, dn);
    mul(dn, 3, hi_, 1, b);
    mul(num, 2, num, 2, nn);
    for (int k = 0; k <= 4; ++k) Q[k] = a[k] + 2 * b[k] + nn[k] * i.c[8];
    deg = 4;
  } else {
    const GeneralDepth& sp = i.kind == GeneralDepth::Rational ? j : i;
    const GeneralDepth& tr = i.kind == GeneralDepth::Rational ? i : j;
    const double* N = tr.c;
    const double* D = tr.c + 4;
    double h[2] = {sp.c[0], sp.c[1]}, m[3] = {sp.c[2], sp.c[3], sp.c[4]};
    double D2[5], a[7], ND[6], b[7], NN[7];
    mul(D, 2, D, 2, D2);
    mul(D2, 4, m, 2, a);
    mul(N, 3, D, 2, ND);
    mul(ND, 5, h, 1, b);
    mul(N, 3, N, 3, NN);
    for (int k = 0; k <= 6; ++k) Q[k] = a[k] + 2 * b[k] + NN[k] * sp.c[8];
    deg = 6;
  }
  double scale = 0;
  for (int k = 0; k <= deg; ++k) scale = std::max(scale, std::fabs(Q[k]));
  if (scale == 0) return 0;  // identical surfaces along this ray: ties go to the lower id
  for (int k = 0; k <= deg; ++k) Q[k] /= scale;
  return poly_roots_in(Q, deg, lo, hi, out);  // at most deg <= 6 <= kMaxCrossings roots
}

namespace {

// Breakpoints of a pixel's coverage along the segment: t = 0 and 1, plus the roots of the three
// quadratic edge functions and of the cubic near-plane function (moving triangles, §3.3), or of
// the sphere's two quadratics and one linear function (§4). Between two breakpoints the coverage
// does not change, so a pixel has at most one interval per pair of consecutive breakpoints:
// kMaxIntervals is that bound, so that no interval is ever dropped (the coverage functions throw
// rather than overflow, which would be a bug in the bound).
constexpr int kMaxTriangleBreakpoints = 1 + 3 * 2 + 3 + 1;
constexpr int kMaxSphereBreakpoints = 1 + 2 + 1 + 2 + 1;
constexpr int kMaxIntervals = std::max(kMaxTriangleBreakpoints, kMaxSphereBreakpoints) - 1;

// Sorts a few doubles in place (std::sort on a tiny fixed array trips GCC's -Warray-bounds).
void sort_small(double* a, int n) {
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && a[j] < a[j - 1]; --j) std::swap(a[j], a[j - 1]);
}  // docs/visibility-math.md §3.3: at most 5 per moving triangle and pixel

// ---- Moving triangles (§3.1-3.3) ------------------------------------------------------------

struct MovingTriangle {
  bool moving = false;
  StaticTriangle lin;  // when !moving: the static kernel's linear quantities
  Vec3 K0[3], K1[3], K2[3];
  double rho[3];
  Vec3 n0, n1, n2;
  double N[4];
};

// Lexicographic order of the 6-tuples (P0, P1) (§3.1 canonical edges).
bool less6(Vec3 a0, Vec3 a1, Vec3 b0, Vec3 b1) {
  if (a0 != b0) return lex_less(a0, b0);
  return lex_less(a1, b1);
}

MovingTriangle prepare_moving(const std::array<Vec3, 3>& c0, const std::array<Vec3, 3>& c1, Vec3 e0,
                              Vec3 e1) {
  MovingTriangle mt;
  mt.moving = c0 != c1;
  const Vec3 delta = e1 - e0;
  if (!mt.moving) {
    Vec3 c[3] = {c0[0], c0[1], c0[2]};
    mt.lin = prepare_static_triangle(c, e0, e1);
    return mt;
  }
  Vec3 r0[3], r1[3];  // re-centred at e0 (docs/visibility-math.md §6)
  for (int k = 0; k < 3; ++k) {
    r0[k] = c0[k] - e0;
    r1[k] = c1[k] - e0;
  }
  for (int e = 0; e < 3; ++e) {
    int i = e, j = (e + 1) % 3;
    bool forward = !less6(c0[j], c1[j], c0[i], c1[i]);
    int p = forward ? i : j, q = forward ? j : i;
    Vec3 E0 = r0[q] - r0[p], E1 = (r1[q] - r0[q]) - (r1[p] - r0[p]);
    Vec3 W0 = -r0[p], W1 = delta - (r1[p] - r0[p]);
    mt.K0[e] = cross(E0, W0);
    mt.K1[e] = cross(E0, W1) + cross(E1, W0);
    mt.K2[e] = cross(E1, W1);
    mt.rho[e] = forward ? 1.0 : -1.0;
  }
  Vec3 f0 = r0[1] - r0[0], f1 = (r1[1] - r0[1]) - (r1[0] - r0[0]);
  Vec3 g0 = r0[2] - r0[0], g1 = (r1[2] - r0[2]) - (r1[0] - r0[0]);
  mt.n0 = cross(f0, g0);
  mt.n1 = cross(f0, g1) + cross(f1, g0);
  mt.n2 = cross(f1, g1);
  Vec3 h0 = r0[0], h1 = (r1[0] - r0[0]) - delta;
  mt.N[0] = dot(mt.n0, h0);
  mt.N[1] = dot(mt.n0, h1) + dot(mt.n1, h0);
  mt.N[2] = dot(mt.n1, h1) + dot(mt.n2, h0);
  mt.N[3] = dot(mt.n2, h1);
  return mt;
}

struct Interval {
  double lo, hi;
  GeneralDepth depth;
};

// Coverage intervals of a moving triangle at pixel direction d: the two-branch rule (§3.3).
int moving_coverage(const MovingTriangle& mt, Vec3 d, Vec3 S, Vec3 T, double near, Interval* out) {
  if (!mt.moving) {
    double lo, hi;
    LinearDepth ld;
    if (!static_coverage(mt.lin, d, S, T, near, lo, hi, ld)) return 0;
    out[0].lo = lo;
    out[0].hi = hi;
    out[0].depth.kind = GeneralDepth::Rational;
    double* c = out[0].depth.c;
    c[0] = ld.n0;
    c[1] = -ld.n1;
    c[2] = c[3] = 0;
    c[4] = ld.dn;
    c[5] = c[6] = 0;
    return 1;
  }
  double Sx[3][3];
  for (int e = 0; e < 3; ++e) {
    double s0 = dot(d, mt.K0[e]), s1 = dot(d, mt.K1[e]), s2 = dot(d, mt.K2[e]);
    if (s0 == 0 && s1 == 0 && s2 == 0) {  // persistent on-edge tie: d + eps S + eps^2 T (§2.5)
      s0 = dot(S, mt.K0[e]), s1 = dot(S, mt.K1[e]), s2 = dot(S, mt.K2[e]);
      if (s0 == 0 && s1 == 0 && s2 == 0)
        s0 = dot(T, mt.K0[e]), s1 = dot(T, mt.K1[e]), s2 = dot(T, mt.K2[e]);
    }
    Sx[e][0] = mt.rho[e] * s0;
    Sx[e][1] = mt.rho[e] * s1;
    Sx[e][2] = mt.rho[e] * s2;
  }
  double D[3] = {dot(d, mt.n0), dot(d, mt.n1), dot(d, mt.n2)};
  double G[4] = {mt.N[0] - near * D[0], mt.N[1] - near * D[1], mt.N[2] - near * D[2], mt.N[3]};
  double pts[kMaxTriangleBreakpoints];
  int np = 0;
  pts[np++] = 0;
  for (int e = 0; e < 3; ++e) np += poly_roots_in(Sx[e], 2, 0, 1, pts + np);
  np += poly_roots_in(G, 3, 0, 1, pts + np);
  pts[np++] = 1;
  sort_small(pts + 1, np - 2);
  int n = 0;
  for (int k = 0; k + 1 < np; ++k) {
    double a = pts[k], b = pts[k + 1];
    if (!(a < b)) continue;
    double m = 0.5 * (a + b);
    double s0 = poly_eval(Sx[0], 2, m), s1 = poly_eval(Sx[1], 2, m), s2 = poly_eval(Sx[2], 2, m);
    double g = poly_eval(G, 3, m);
    bool on = (s0 > 0 && s1 > 0 && s2 > 0 && g > 0) || (s0 < 0 && s1 < 0 && s2 < 0 && g < 0);
    if (!on) continue;
    if (n > 0 && out[n - 1].hi == a) {
      out[n - 1].hi = b;
      continue;
    }
    if (n == kMaxIntervals)
      throw std::logic_error("moving_coverage: more intervals than breakpoints");
    out[n].lo = a;
    out[n].hi = b;
    out[n].depth.kind = GeneralDepth::Rational;
    for (int c = 0; c < 4; ++c) out[n].depth.c[c] = mt.N[c];
    for (int c = 0; c < 3; ++c) out[n].depth.c[4 + c] = D[c];
    ++n;
  }
  return n;
}

// ---- Spheres (§4) -------------------------------------------------------------------------

struct MovingSphere {
  Vec3 w0, w1;  // w(s) = v(s) - o(s) = w0 + s w1 (re-centred at e0)
  double r;
};

int sphere_coverage(const MovingSphere& sp, Vec3 d, double near, Interval* out) {
  const double dd = dot(d, d), r2 = sp.r * sp.r;
  Vec3 c0 = cross(d, sp.w0), c1 = cross(d, sp.w1);
  double g[3] = {r2 * dd - dot(c0, c0), -2.0 * dot(c0, c1), -dot(c1, c1)};  // cross form
  double hn[2] = {dot(d, sp.w0) + near * dd, dot(d, sp.w1)};
  Vec3 z0 = sp.w0 + d * near;
  double M[3] = {dot(z0, z0) - r2, 2.0 * dot(z0, sp.w1), dot(sp.w1, sp.w1)};
  double pts[kMaxSphereBreakpoints];
  int np = 0;
  pts[np++] = 0;
  np += poly_roots_in(g, 2, 0, 1, pts + np);
  np += poly_roots_in(hn, 1, 0, 1, pts + np);
  np += poly_roots_in(M, 2, 0, 1, pts + np);
  pts[np++] = 1;
  sort_small(pts + 1, np - 2);
  GeneralDepth base;
  base.c[0] = dot(d, sp.w0);
  base.c[1] = dot(d, sp.w1);
  base.c[2] = dot(sp.w0, sp.w0) - r2;
  base.c[3] = 2.0 * dot(sp.w0, sp.w1);
  base.c[4] = dot(sp.w1, sp.w1);
  base.c[5] = g[0];
  base.c[6] = g[1];
  base.c[7] = g[2];
  base.c[8] = dd;
  for (int k = 0; k < 3; ++k) {
    base.c[9 + k] = sp.w0[k];
    base.c[12 + k] = sp.w1[k];
  }
  base.c[15] = sp.r;
  int n = 0;
  for (int k = 0; k + 1 < np; ++k) {
    double a = pts[k], b = pts[k + 1];
    if (!(a < b)) continue;
    double m = 0.5 * (a + b);
    double gv = poly_eval(g, 2, m), hv = poly_eval(hn, 1, m), mv = poly_eval(M, 2, m);
    GeneralDepth::Kind kind;
    if (gv > 0 && mv < 0)
      kind = GeneralDepth::SphereFar;  // the eye (near point) is inside: the far root
    else if (gv > 0 && hv < 0 && mv > 0)
      kind = GeneralDepth::SphereNear;
    else
      continue;
    if (n > 0 && out[n - 1].hi == a && out[n - 1].depth.kind == kind) {
      out[n - 1].hi = b;
      continue;
    }
    if (n == kMaxIntervals)
      throw std::logic_error("sphere_coverage: more intervals than breakpoints");
    out[n].lo = a;
    out[n].hi = b;
    out[n].depth = base;
    out[n].depth.kind = kind;
    ++n;
  }
  return n;
}

// Pixel bounds of a sphere seen from a moving eye (§5.2): the tangent-plane boxes at both ends,
// and their bounding box (the projection of the swept capsule is the convex hull of the two end
// projections, which the union of the two boxes does not always contain). When the sphere reaches
// the near plane at an end: the projection of its clipped bounding box.
bool sphere_pixel_bounds(Vec3 c0w, Vec3 c1w, double r, const FaceAxes& ax, double near, int n,
                         int& x0, int& x1, int& y0, int& y1) {
  double z0 = dot(ax.F, c0w), z1 = dot(ax.F, c1w);
  if (z0 + r <= near && z1 + r <= near) return false;  // the swept ball is behind the near plane
  double umin = INFINITY, umax = -INFINITY, wmin = INFINITY, wmax = -INFINITY;
  if (z0 - r <= near || z1 - r <= near) {
    // The swept ball reaches the near plane: bound it by the box around both end balls (face
    // coordinates), clip the box at z >= near and project its 8 corners (a perspective image of a
    // convex set in z > 0 is convex, so the corners give its extent).
    Vec3 lo{std::min(dot(ax.S, c0w), dot(ax.S, c1w)) - r,
            std::min(dot(ax.T, c0w), dot(ax.T, c1w)) - r, std::max(near, std::min(z0, z1) - r)};
    Vec3 hi{std::max(dot(ax.S, c0w), dot(ax.S, c1w)) + r,
            std::max(dot(ax.T, c0w), dot(ax.T, c1w)) + r, std::max(z0, z1) + r};
    for (int k = 0; k < 8; ++k) {
      double x = (k & 1) ? hi.x : lo.x, y = (k & 2) ? hi.y : lo.y, z = (k & 4) ? hi.z : lo.z;
      umin = std::min(umin, x / z);
      umax = std::max(umax, x / z);
      wmin = std::min(wmin, y / z);
      wmax = std::max(wmax, y / z);
    }
  }
  for (Vec3 cw : {c0w, c1w}) {
    if (z0 - r <= near || z1 - r <= near) break;
    double cx = dot(ax.S, cw), cy = dot(ax.T, cw), cz = dot(ax.F, cw);
    double den = cz * cz - r * r;
    double su = std::sqrt(std::max(0.0, cx * cx + cz * cz - r * r));
    double sw = std::sqrt(std::max(0.0, cy * cy + cz * cz - r * r));
    umin = std::min(umin, (cx * cz - r * su) / den);
    umax = std::max(umax, (cx * cz + r * su) / den);
    wmin = std::min(wmin, (cy * cz - r * sw) / den);
    wmax = std::max(wmax, (cy * cz + r * sw) / den);
  }
  if (!(umin <= umax)) return false;
  double m = kFootprintMargin +
             kFootprintRelativeMargin *
                 std::max({std::fabs(umin), std::fabs(umax), std::fabs(wmin), std::fabs(wmax)});
  return face_box_pixels(umin, umax, wmin, wmax, m, n, x0, x1, y0, y1);
}

// ---- One run ------------------------------------------------------------------------------

struct Run {
  Vec3 e0, e1;        // eye at s = 0 and s = 1
  size_t k0, k1;      // key states at s = 0 and s = 1 (vertices and sphere centres)
  double t0, t1;      // segment parameter at s = 0, 1
  double tau0, tau1;  // animation time at s = 0, 1
  bool diagonal;      // part of the Diagonal mode (its pieces map onto t)
};

// ---- Compact pixel lists -----------------------------------------------------------------
// A GeneralDepth is 136 bytes, so a GeneralPiece is 160; the dense lists of vegetation (a grass
// field ends with 150 pieces a pixel on average, up to 965) spent most of their time moving them
// (vector growth, memmove on insertion, page faults). Inside a tile the lists hold a 32-byte
// piece whose depth is a pointer into a per-tile pool, one entry per inserted interval that
// changed its list. The handle forwards every question to the pointed-to depth (same_depth
// compares the coefficients unless the pointers are equal), so the lists are those of
// GeneralPiece bit for bit; finish_pixel copies the depths out for SegmentResult::general_pieces.
struct DepthRef {
  const GeneralDepth* d = nullptr;
  double at(double t) const { return d->at(t); }
};
int depth_crossings(const DepthRef& i, const DepthRef& j, double lo, double hi, double* out) {
  return depth_crossings(*i.d, *j.d, lo, hi, out);
}
bool same_depth(const DepthRef& a, const DepthRef& b) {
  return a.d == b.d || same_depth(*a.d, *b.d);
}
using CompactPiece = PieceT<DepthRef>;

// The depths a tile's lists point at, in the order they were inserted: chunks that never move
// (pointers stay valid while the pool grows), kept from tile to tile and reused. (Chunks of their
// own per pixel were measured slower on the grass field.)
class DepthPool {
 public:
  GeneralDepth* push(const GeneralDepth& d) {
    if (used_ == chunks_.size() * kChunk) chunks_.emplace_back(new GeneralDepth[kChunk]);
    GeneralDepth* slot = &chunks_[used_ / kChunk][used_ % kChunk];
    *slot = d;
    ++used_;
    return slot;
  }
  void pop() { --used_; }  // the last push, which no list points at
  void clear() { used_ = 0; }
  size_t bytes() const { return chunks_.size() * kChunk * sizeof(GeneralDepth); }

 private:
  static constexpr size_t kChunk = 1024;
  std::vector<std::unique_ptr<GeneralDepth[]>> chunks_;
  size_t used_ = 0;
};

// One run of moving triangles and spheres for the tile driver (tile_driver.h): footprints of the
// six eye-relative corners (triangles) or of the swept sphere, coverage as intervals with general
// depths, exact depth culling with each piece's primitive's farthest depth over the run.
class DynamicKind {
 public:
  struct Scratch {
    std::vector<std::vector<CompactPiece>> lists;
    std::vector<double> far;  // per pixel: farthest zmax over its pieces once they cover [0,1]
    std::vector<std::vector<TieRecord>> ties;  // per pixel (CoplanarRule::Both)
    DepthPool depths;                          // what the pieces of `lists` point at
  };

  DynamicKind(const Scene& scene, const Run& run, const SegmentOptions& opt,
              std::vector<std::vector<GeneralPiece>>* pieces)
      : scene_(scene),
        run_(run),
        opt_(opt),
        pieces_(pieces),
        ntri_(scene.triangle_count()),
        P0_(state_of(scene.positions, run.k0)),
        P1_(state_of(scene.positions, run.k1)),
        C0_(state_of(scene.sphere_centers, run.k0)),
        C1_(state_of(scene.sphere_centers, run.k1)) {
    const size_t nprim = count();
    zmax_.resize(nprim);
    keep_ties_ = opt.coplanar == CoplanarRule::Both;
    far_scale_ = keep_ties_ ? 1 + 2 * opt.eps_z : 1.0;  // as in the static kernel
    // The faces each triangle can reach.
    faces_ = classify_faces(ntri_, opt, [this](size_t t, Vec3* rel) {
      relative_corners(t, rel);
      return 6;
    });
  }

  size_t count() const { return ntri_ + scene_.sphere_count(); }

  Scratch make_scratch(int ts) const {
    const size_t n = size_t(ts) * size_t(ts);
    return Scratch{std::vector<std::vector<CompactPiece>>(n), std::vector<double>(n),
                   std::vector<std::vector<TieRecord>>(n), DepthPool()};
  }

  void begin_tile(Scratch& sc) const { sc.depths.clear(); }
  // No see-through primitives here (segment_visibility refuses them in dynamic scenes).
  void finish_tile(Scratch&, int, const TileRect&, const FaceAxes&, FoundMarks&,
                   SegmentStats&) const {}
  size_t held_bytes(const Scratch& sc) const { return sc.depths.bytes(); }

  // Bounds of the view depth of every primitive over the run on this face: any hit of it at any s
  // has zmin <= lambda <= zmax (the eye-relative triangle lies in the hull of its six eye-relative
  // vertices; the sphere within r of its eye-relative centre, which moves linearly).
  bool bounds(size_t p, int face, const FaceAxes& axes, int* b, double& zmin) {
    if (p < ntri_) {
      if (!(faces_[p] >> face & 1)) return false;
      Vec3 rel[6];
      relative_corners(p, rel);
      double lo = INFINITY, hi = -INFINITY;
      for (const Vec3& q : rel) {
        lo = std::min(lo, dot(axes.F, q));
        hi = std::max(hi, dot(axes.F, q));
      }
      zmin = lo;
      zmax_[p] = hi;
      double z;  // footprint_bounds: the hull's rectangle without the hull (bit-identical)
      return footprint_bounds(rel, 6, axes, opt_.near, opt_.resolution, b[0], b[1], b[2], b[3], z);
    }
    const size_t s = p - ntri_;
    const double radius = scene_.sphere_radius[s];
    const double z0 = dot(axes.F, C0_[s] - run_.e0), z1 = dot(axes.F, C1_[s] - run_.e1);
    zmin = std::min(z0, z1) - radius;
    zmax_[p] = std::max(z0, z1) + radius;
    return sphere_pixel_bounds(C0_[s] - run_.e0, C1_[s] - run_.e1, radius, axes, opt_.near,
                               opt_.resolution, b[0], b[1], b[2], b[3]);
  }

  static constexpr bool kHasBvh = false;  // moving primitives: no tree

  void flush(Scratch&, const TileRect&, const FaceAxes&, SegmentStats&) const {}  // nothing held

  void cover(Scratch& sc, const TileItem& item, const int* b, const TileRect& rect,
             const FaceAxes& axes, SegmentStats& stats) const {
    const int N = opt_.resolution;
    const uint32_t p = item.id;
    const double tz = double(item.zmin);
    const int y0 = std::max(rect.y0, b[2]), y1 = std::min(rect.y1, b[3]);
    Interval iv[kMaxIntervals];
    // Culling, coverage and insertion at pixel (x, y) with coverage(d, iv) -> interval count.
    auto pixel = [&](int x, int y, auto&& coverage) {
      const size_t k = rect.index(x, y);
      if (opt_.depth_culling && tz > sc.far[k]) {
        ++stats.culled_pairs;
        return;
      }
      ++stats.pair_tests;
      const int n = coverage(pixel_direction(axes, x, y, N), iv);
      if (n) ++stats.covered_pairs;
      bool changed = false;
      const TieRule tie{opt_.eps_z, keep_ties_ ? &sc.ties[k] : nullptr};
      for (int i = 0; i < n; ++i) {
        const GeneralDepth* d = sc.depths.push(iv[i].depth);
        if (insert_piece(sc.lists[k], CompactPiece{iv[i].lo, iv[i].hi, p, DepthRef{d}}, tie))
          changed = true;
        else
          sc.depths.pop();  // the list is unchanged: nothing points at it
      }
      if (changed && opt_.depth_culling) update_far(sc, k);
    };
    if (p < ntri_) {
      auto a0 = corners(P0_, p), a1 = corners(P1_, p);
      MovingTriangle mt = prepare_moving(a0, a1, run_.e0, run_.e1);
      if (!mt.moving && mt.lin.n == Vec3{0, 0, 0}) return;  // degenerate (H5)
      Vec3 rel[6];
      relative_corners(p, rel);
      Vec2 hull[kMaxFootprintPoints];
      double margin;
      const int hull_size = compute_footprint_hull(rel, 6, axes, opt_.near, hull, margin);
      auto coverage = [&](Vec3 d, Interval* out) {
        return moving_coverage(mt, d, axes.S, axes.T, opt_.near, out);
      };
      for (int y = y0; y <= y1; ++y) {
        int x0, x1;
        if (!footprint_row_span(hull, hull_size, margin, N, y, x0, x1)) continue;
        for (int x = std::max(x0, rect.x0); x <= std::min(x1, rect.x1); ++x) pixel(x, y, coverage);
      }
    } else {
      const size_t s = p - ntri_;
      MovingSphere sp{run_.e0 - C0_[s], (run_.e1 - run_.e0) - (C1_[s] - C0_[s]),
                      scene_.sphere_radius[s]};
      auto coverage = [&](Vec3 d, Interval* out) { return sphere_coverage(sp, d, opt_.near, out); };
      for (int y = y0; y <= y1; ++y)
        for (int x = std::max(rect.x0, b[0]); x <= std::min(rect.x1, b[1]); ++x)
          pixel(x, y, coverage);
    }
  }

  void finish_pixel(Scratch& sc, size_t k, int face, int x, int y, FoundMarks& found) const {
    const auto& l = sc.lists[k];
    // Length in the segment parameter (Diagonal) or in animation time (eye fixed).
    const double span = std::max(std::fabs(run_.t1 - run_.t0), std::fabs(run_.tau1 - run_.tau0));
    for_each_visible(l, sc.ties[k], [&](uint32_t id, double t0, double t1) {
      double len = (t1 - t0) * span;
      if (!(len > opt_.eps_len)) return;
      double sm = 0.5 * (t0 + t1);
      bool sph = id >= ntri_;
      Witness w;
      w.tri = sph ? uint32_t(id - ntri_) : id;
      w.is_sphere = sph;
      w.face = face;
      w.x = x;
      w.y = y;
      w.t = run_.t0 + sm * (run_.t1 - run_.t0);
      w.tau = run_.tau0 + sm * (run_.tau1 - run_.tau0);
      found.mark(id, len, w);
    });
    if (!pieces_ || !run_.diagonal) return;
    const int N = opt_.resolution;
    auto& dst = (*pieces_)[(size_t(face) * N + y) * N + x];
    for (const CompactPiece& c : l) {
      GeneralPiece pc{c.t0, c.t1, c.id, *c.depth.d};
      pc.t0 = run_.t0 + pc.t0 * (run_.t1 - run_.t0);
      pc.t1 = pc.t1 == 1.0 ? run_.t1 : run_.t0 + pc.t1 * (run_.t1 - run_.t0);
      if (!(pc.t0 < pc.t1)) continue;
      // Depth functions stay in the run's local parameter; callers that evaluate them map t back
      // with (t - run.t0) / (run.t1 - run.t0).
      if (!dst.empty() && dst.back().id == pc.id && dst.back().t1 == pc.t0 && pc.t0 == run_.t0)
        dst.back().t1 = pc.t1;
      else
        dst.push_back(pc);
    }
  }

 private:
  static const std::vector<Vec3>& state_of(const std::vector<std::vector<Vec3>>& states, size_t k) {
    static const std::vector<Vec3> none;
    return states.empty() ? none : states[std::min(k, states.size() - 1)];
  }
  std::array<Vec3, 3> corners(const std::vector<Vec3>& P, size_t t) const {
    const auto& ix = scene_.triangles[t];
    return {P[ix[0]], P[ix[1]], P[ix[2]]};
  }
  void relative_corners(size_t t, Vec3* rel) const {
    auto a0 = corners(P0_, t), a1 = corners(P1_, t);
    const Vec3 r[6] = {a0[0] - run_.e0, a0[1] - run_.e0, a0[2] - run_.e0,
                       a1[0] - run_.e1, a1[1] - run_.e1, a1[2] - run_.e1};
    std::copy(r, r + 6, rel);
  }
  // A covered pixel's far: the largest zmax over the primitives of its pieces.
  void update_far(Scratch& sc, size_t k) const {
    const auto& l = sc.lists[k];
    // A list that covers [0, 1] keeps covering it (insertions only add coverage), and its far is
    // finite from then on: walk the list for gaps only until it first covers.
    if (sc.far[k] == INFINITY && !covers_segment(l)) return;
    double f = -INFINITY;
    for (const CompactPiece& pc : l) f = std::max(f, zmax_[pc.id]);
    sc.far[k] = f * far_scale_;
  }

  const Scene& scene_;
  const Run& run_;
  const SegmentOptions& opt_;
  std::vector<std::vector<GeneralPiece>>* pieces_;
  size_t ntri_;
  const std::vector<Vec3>&P0_, &P1_, &C0_, &C1_;
  std::vector<double> zmax_;  // per primitive, on the current face (bounds() writes it)
  std::vector<uint8_t> faces_;
  bool keep_ties_ = false;
  double far_scale_ = 1.0;
};

}  // namespace

SegmentResult dynamic_segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1,
                                         const SegmentOptions& opt) {
  assert(opt.resolution >= 1 && opt.near > 0 && opt.tile_size >= 0);
  if (opt.tile_size == 0) {  // the kernel's choice
    SegmentOptions o = opt;
    o.tile_size = kDynamicTileSize;
    return dynamic_segment_visibility(scene, v0, v1, o);
  }
  auto start = std::chrono::steady_clock::now();
  const size_t K = std::max<size_t>(1, scene.state_count());
  const size_t ntri = scene.triangle_count(), nprim = ntri + scene.sphere_count();
  auto tau_of = [K](size_t k) { return K == 1 ? 0.0 : double(k) / double(K - 1); };
  std::vector<Run> runs;
  // Diagonal: tau = t; one run per state interval (a single frozen run for one state).
  if (K == 1) {
    runs.push_back({v0, v1, 0, 0, 0.0, 1.0, 0.0, 0.0, true});
  } else {
    for (size_t k = 0; k + 1 < K; ++k) {
      double ta = tau_of(k), tb = tau_of(k + 1);
      runs.push_back({lerp(v0, v1, ta), lerp(v0, v1, tb), k, k + 1, ta, tb, ta, tb, true});
    }
  }
  if (opt.mode == DynamicMode::Decoupled && K > 1) {
    for (size_t k = 0; k + 1 < K; ++k) {
      runs.push_back({v0, v0, k, k + 1, 0.0, 0.0, tau_of(k), tau_of(k + 1), false});
      runs.push_back({v1, v1, k, k + 1, 1.0, 1.0, tau_of(k), tau_of(k + 1), false});
    }
    for (size_t k = 0; k < K; ++k)
      runs.push_back({v0, v1, k, k, 0.0, 1.0, tau_of(k), tau_of(k), false});
  }
  SegmentResult result;
  if (opt.want_pieces) result.general_pieces.resize(size_t(6) * opt.resolution * opt.resolution);
  tbb::enumerable_thread_specific<FoundMarks> found_by_thread(
      [&] { return FoundMarks(nprim, opt.want_witnesses); });
  const int tiles_x = tiles_per_side(opt.resolution, opt.tile_size);
  std::vector<SegmentStats> stats(size_t(6) * tiles_x * tiles_x);
  for (const Run& run : runs) {
    DynamicKind kind(scene, run, opt, opt.want_pieces ? &result.general_pieces : nullptr);
    run_tiles(kind, opt, found_by_thread, stats);
  }
  for (const SegmentStats& ts : stats) result.stats.add(ts);
  std::vector<uint8_t> seen;
  std::vector<Witness> best;
  reduce_found(found_by_thread, nprim, opt.want_witnesses, seen, best);
  for (size_t p = 0; p < nprim; ++p) {
    if (!seen[p]) continue;
    if (p < ntri)
      result.visible.push_back(uint32_t(p));
    else
      result.visible_spheres.push_back(uint32_t(p - ntri));
    if (opt.want_witnesses) result.witnesses.push_back(best[p]);
  }
  result.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vislib
