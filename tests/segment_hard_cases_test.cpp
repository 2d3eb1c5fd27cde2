// The hard cases H1-H13 of docs/visibility-math.md §6, one named test each, with an
// exact CGAL oracle where arithmetic is the point.
#include <CGAL/Gmpq.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "tests/scene_builders.h"
#include "tests/support/ray_oracle.h"
#include "vislib/base/polynomial.h"
#include "vislib/kernel/dynamic_visibility.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/kernel/static_coverage.h"

using namespace vislib;
using vislib_test::soup;

namespace {

const Vec3 kS{1, 0, 0}, kT{0, -1, 0};  // +Z face axes of the binding table (identity R)

struct Cov {
  bool covered = false;
  double lo = 0, hi = 0;
  LinearDepth depth;
};
Cov coverage(std::array<Vec3, 3> tri, Vec3 v0, Vec3 v1, Vec3 d, double near = 1e-9, Vec3 S = kS,
             Vec3 T = kT) {
  Vec3 c[3] = {tri[0], tri[1], tri[2]};
  StaticTriangle st = prepare_static_triangle(c, v0, v1);
  Cov r;
  r.covered = static_coverage(st, d, S, T, near, r.lo, r.hi, r.depth);
  return r;
}

PieceList composite(const std::vector<std::pair<uint32_t, Cov>>& in) {
  PieceList l;
  for (const auto& [id, c] : in)
    if (c.covered) insert_piece(l, Piece{c.lo, c.hi, id, c.depth});
  return l;
}

}  // namespace

TEST(SegmentHardCases, H1_EdgeThroughPixelCentreSplitsAtDyadicTimeBitExactly) {
  Vec3 v0{0, 3, 0}, v1{0, -1, 0}, d{0.0625, -0.5, 1};
  Cov a = coverage({Vec3{-1, -1, 4}, {1, -1, 4}, {0, 2, 4}}, v0, v1, d);
  Cov b = coverage({Vec3{1, -1, 4}, {-1, -1, 4}, {0, -4, 4}}, v0, v1, d);
  ASSERT_TRUE(a.covered);
  ASSERT_TRUE(b.covered);
  EXPECT_EQ(a.lo, 0.0);
  EXPECT_EQ(a.hi, 0.5);
  EXPECT_EQ(b.lo, 0.5);
  EXPECT_EQ(b.hi, 1.0);
  EXPECT_EQ(a.hi, b.lo);  // bit-equal: no crack, no overlap
}

TEST(SegmentHardCases, H2_PersistentOnEdgeTieGivesExactlyOneTriangleAtEveryPixelOfTheRow) {
  // Segment parallel to the shared edge, the row's rays lie in the plane of edge and segment.
  std::array<Vec3, 3> t1{Vec3{-8, 0, 6}, {8, 0, 6}, {0, 5, 6}};
  std::array<Vec3, 3> t2{Vec3{8, 0, 6}, {-8, 0, 6}, {0, -5, 6}};
  Vec3 v0{0, 0, 0}, v1{1, 0, 0};
  const int N = 5;
  FaceAxes ax = face_axes(4, Mat3{});  // +Z
  int winners_t1 = 0, winners_t2 = 0;
  for (int x = 0; x < N; ++x) {
    Vec3 d = pixel_direction(ax, x, 2, N);
    ASSERT_EQ(d.y, 0.0);
    Cov a = coverage(t1, v0, v1, d, 1e-9, ax.S, ax.T),
        b = coverage(t2, v0, v1, d, 1e-9, ax.S, ax.T);
    EXPECT_NE(a.covered, b.covered) << "pixel " << x;
    const Cov& w = a.covered ? a : b;
    EXPECT_EQ(w.lo, 0.0);
    EXPECT_EQ(w.hi, 1.0);
    (a.covered ? winners_t1 : winners_t2)++;
    EXPECT_TRUE(std::isfinite(w.depth.at(0)) && std::isfinite(w.depth.at(1)));
  }
  // With the binding table, T = (0,-1,0) on +Z: the perturbation d + eps S + eps^2 T tilts the
  // ray towards -y, so T2 (the lower triangle) wins. (An earlier table with +y named
  // T1: docs/visibility-math.md §6.)
  EXPECT_EQ(winners_t2, N);
  // A = 0, B != 0: constant coverage over [0,1], no NaN/inf.
  Cov c = coverage(t1, v0, v1, Vec3{0.1, 0.2, 1});
  ASSERT_TRUE(c.covered);
  EXPECT_EQ(c.lo, 0.0);
  EXPECT_EQ(c.hi, 1.0);
}

TEST(SegmentHardCases, H3_EyeCrossingThePlaneSeesOnlyTheFrontHalf) {
  std::array<Vec3, 3> t{Vec3{-10, -10, 5}, {10, -10, 5}, {0, 10, 5}};
  Vec3 v0{0, 0, 0}, v1{0, 0, 10};
  Cov f = coverage(t, v0, v1, Vec3{.1, .1, 1}, 0.0);
  Cov b = coverage(t, v0, v1, Vec3{.1, .1, -1}, 0.0);
  ASSERT_TRUE(f.covered);
  ASSERT_TRUE(b.covered);
  EXPECT_EQ(f.lo, 0.0);
  EXPECT_EQ(f.hi, 0.5);
  EXPECT_EQ(b.lo, 0.5);
  EXPECT_EQ(b.hi, 1.0);
}

TEST(SegmentHardCases, H4_TriangleEdgeOnAlongTheWholeSegmentCoversNothing) {
  Scene s = soup({{Vec3{-1, 0, 2}, {1, 0, 2}, {0, 0, 6}}});
  SegmentOptions o;
  o.resolution = 64;
  o.want_pieces = true;
  auto r = segment_visibility(s, {0, 0, 0}, {0, 0, 3}, o);
  EXPECT_TRUE(r.visible.empty());
  EXPECT_EQ(r.stats.covered_pairs, 0u);
}

TEST(SegmentHardCases, H5_DegenerateTrianglesAreNeverVisible) {
  Scene s = soup({{Vec3{-1, -1, 3}, {0, 0, 3}, {1, 1, 3}},    // collinear
                  {Vec3{-1, -1, 3}, {-1, -1, 3}, {1, 0, 3}},  // repeated vertex
                  {Vec3{2, 2, 2}, {2, 2, 2}, {2, 2, 2}}});    // a point
  SegmentOptions o;
  o.resolution = 64;
  auto r = segment_visibility(s, {-0.5, 0, 0}, {0.5, 0.2, 0}, o);
  EXPECT_TRUE(r.visible.empty());
}

TEST(SegmentHardCases, H6_BackgroundBehindAJitteredSharedEdgeGridNeverLeaks) {
  Scene s;
  vislib_test::add_grid(
      s, 16, -20, 20, -20, 20,
      [](double x, double y) { return 5 + 0.3 * std::sin(x) * std::cos(y); }, 7, 0.8);
  uint32_t first_bg = uint32_t(s.triangle_count());
  vislib_test::add_quad(s, {-6, -6, 10}, {6, -6, 10}, {6, 6, 10}, {-6, 6, 10});
  SegmentOptions o;
  o.resolution = 96;
  o.want_pieces = true;
  o.eps_len = 0;  // exact mode: not even a 1e-16 crack may appear
  auto r = segment_visibility(s, {-0.7, -0.3, 0}, {0.6, 0.4, 0.1}, o);
  for (uint32_t id : r.visible) EXPECT_LT(id, first_bg) << "background leaked";
  size_t pieces = 0;
  for (const auto& l : r.pieces)
    for (const auto& p : l) {
      EXPECT_LT(p.id, first_bg);
      ++pieces;
    }
  EXPECT_GT(pieces, 1000u);
}

TEST(SegmentHardCases, H7_TJunctionLeaksNothingExactAndNothingAfterEpsLenWhenRounded) {
  for (bool rounded : {false, true}) {
    // Edge PQ of the big triangle is shared by two small triangles meeting at M on it.
    Vec3 P{-4, -1, 5}, Q{4, 1.3, 5}, M = (P + Q) * 0.5;
    if (rounded) M = M + Vec3{1e-15, -2e-15, 0};
    Scene s = soup({{P, Q, Vec3{0, 8, 5}},
                    {M, P, Vec3{-3, -8, 5}},
                    {Q, M, Vec3{-3, -8, 5}},
                    {Q, Vec3{-3, -8, 5}, Vec3{6, -8, 5}}});
    uint32_t bg = uint32_t(s.triangle_count());
    vislib_test::add_quad(s, {-2, -2, 9}, {2, -2, 9}, {2, 2, 9}, {-2, 2, 9});
    SegmentOptions o;
    o.resolution = 128;
    o.want_pieces = true;
    auto r = segment_visibility(s, {-0.3, -0.2, 0}, {0.3, 0.25, 0}, o);
    EXPECT_TRUE(std::find(r.visible.begin(), r.visible.end(), bg) == r.visible.end() &&
                std::find(r.visible.begin(), r.visible.end(), bg + 1) == r.visible.end())
        << (rounded ? "rounded" : "exact");
    double worst = 0;
    for (const auto& l : r.pieces)
      for (const auto& p : l)
        if (p.id >= bg) worst = std::max(worst, p.t1 - p.t0);
    if (!rounded) {
      EXPECT_EQ(worst, 0.0);
    } else {
      EXPECT_LE(worst, 1e-12);
    }
  }
}

TEST(SegmentHardCases, H8_InterpenetratingTrianglesSplitAtTheDepthCrossingInEitherOrder) {
  std::array<Vec3, 3> t1{Vec3{-50, -50, 5}, {50, -50, 5}, {0, 50, 5}};
  std::array<Vec3, 3> t2{Vec3{-50, -50, 4}, {50, -50, 6}, {0, 50, 5}};
  Vec3 v0{-1, 0, 0}, v1{1, 0, 0}, d{0, 0, 1};
  Cov a = coverage(t1, v0, v1, d), b = coverage(t2, v0, v1, d);
  for (int order = 0; order < 2; ++order) {
    PieceList l = order ? composite({{1, a}, {2, b}}) : composite({{2, b}, {1, a}});
    ASSERT_EQ(l.size(), 2u);
    EXPECT_EQ(l[0].id, 2u);
    EXPECT_EQ(l[0].t0, 0.0);
    // The crossing from P = N_i D_j - N_j D_i (docs/visibility-math.md §3.4) is exactly 0.5 here;
    // the slope and offset form (L0 = N0/Dn, L1 = -N1/Dn) gave 0.49999999999998934.
    EXPECT_EQ(l[0].t1, 0.5);
    EXPECT_EQ(l[1].id, 1u);
    EXPECT_EQ(l[1].t0, l[0].t1);
    EXPECT_EQ(l[1].t1, 1.0);
    EXPECT_TRUE(is_valid(l));
  }
}

TEST(SegmentHardCases, H9_CoplanarDuplicatesGoToTheLowerIdAndACloserOffsetWins) {
  std::array<Vec3, 3> t{Vec3{-50, -50, 5}, {50, -50, 5}, {0, 50, 5}};
  Vec3 v0{-1, 0, 0}, v1{1, 0, 0}, d{0, 0, 1};
  Cov c = coverage(t, v0, v1, d);
  for (int order = 0; order < 2; ++order) {
    PieceList l = order ? composite({{7, c}, {3, c}}) : composite({{3, c}, {7, c}});
    ASSERT_EQ(l.size(), 1u);
    EXPECT_EQ(l[0].id, 3u);
    EXPECT_EQ(l[0].t0, 0.0);
    EXPECT_EQ(l[0].t1, 1.0);
  }
  std::array<Vec3, 3> closer = t;
  for (auto& p : closer) p.z -= 1e-12;
  Cov c7 = coverage(closer, v0, v1, d);
  for (int order = 0; order < 2; ++order) {
    PieceList l = order ? composite({{7, c7}, {3, c}}) : composite({{3, c}, {7, c7}});
    ASSERT_EQ(l.size(), 1u);
    EXPECT_EQ(l[0].id, 7u);
  }
}

// H9 with the tie rule: the list is the same as under rule First, and the tie
// records make both ids visible, for exact duplicates and for a 1e-12 offset; a 1e-3 offset is no
// tie (eps_z = 1e-6 of the depth 5).
TEST(SegmentHardCases, H9_CoplanarTiesWithinEpsZMakeBothTrianglesVisibleInEitherOrder) {
  std::array<Vec3, 3> t{Vec3{-50, -50, 5}, {50, -50, 5}, {0, 50, 5}};
  Vec3 v0{-1, 0, 0}, v1{1, 0, 0}, d{0, 0, 1};
  Cov c = coverage(t, v0, v1, d);
  for (double offset : {0.0, 1e-12, 1e-3}) {
    std::array<Vec3, 3> moved = t;
    for (auto& p : moved) p.z -= offset;
    Cov c7 = coverage(moved, v0, v1, d);
    for (int order = 0; order < 2; ++order) {
      PieceList l;
      std::vector<TieRecord> ties;
      TieRule rule{kDefaultEpsZ, &ties};
      if (order) {
        insert_piece(l, Piece{c7.lo, c7.hi, 7, c7.depth}, rule);
        insert_piece(l, Piece{c.lo, c.hi, 3, c.depth}, rule);
      } else {
        insert_piece(l, Piece{c.lo, c.hi, 3, c.depth}, rule);
        insert_piece(l, Piece{c7.lo, c7.hi, 7, c7.depth}, rule);
      }
      ASSERT_EQ(l.size(), 1u);
      EXPECT_EQ(l[0].id, offset == 0.0 ? 3u : 7u);
      std::vector<uint32_t> seen;
      for_each_visible(l, ties, [&](uint32_t id, double t0, double t1) {
        EXPECT_EQ(t0, 0.0);
        EXPECT_EQ(t1, 1.0);
        seen.push_back(id);
      });
      std::sort(seen.begin(), seen.end());
      if (offset < 1e-6)
        EXPECT_EQ(seen, (std::vector<uint32_t>{3, 7})) << offset << " order " << order;
      else
        EXPECT_EQ(seen, (std::vector<uint32_t>{7})) << offset << " order " << order;
    }
  }
}

// Three exact coplanar copies inserted front copy first or last: each is visible (ties are
// followed transitively), and a triangle in front of all three hides every one of them.
TEST(SegmentHardCases, H9_ThreeCoplanarCopiesAreAllVisibleAndAllHiddenTogether) {
  std::array<Vec3, 3> t{Vec3{-50, -50, 5}, {50, -50, 5}, {0, 50, 5}};
  std::array<Vec3, 3> front{Vec3{-50, -50, 4}, {50, -50, 4}, {0, 50, 4}};
  Vec3 v0{-1, 0, 0}, v1{1, 0, 0}, d{0, 0, 1};
  Cov c = coverage(t, v0, v1, d), f = coverage(front, v0, v1, d);
  for (auto ids : {std::vector<uint32_t>{2, 1, 0}, std::vector<uint32_t>{0, 1, 2},
                   std::vector<uint32_t>{1, 2, 0}}) {
    for (bool with_front : {false, true}) {
      PieceList l;
      std::vector<TieRecord> ties;
      TieRule rule{kDefaultEpsZ, &ties};
      if (with_front) insert_piece(l, Piece{f.lo, f.hi, 9, f.depth}, rule);
      for (uint32_t id : ids) insert_piece(l, Piece{c.lo, c.hi, id, c.depth}, rule);
      std::vector<uint32_t> seen;
      for_each_visible(l, ties, [&](uint32_t id, double, double) { seen.push_back(id); });
      std::sort(seen.begin(), seen.end());
      EXPECT_EQ(seen, with_front ? std::vector<uint32_t>{9} : (std::vector<uint32_t>{0, 1, 2}));
    }
  }
}

namespace {
using Q = CGAL::Gmpq;
struct QV {
  Q x, y, z;
};
QV qv(Vec3 a) {
  return {Q(a.x), Q(a.y), Q(a.z)};
}
QV operator-(const QV& a, const QV& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Q qdot(const QV& a, const QV& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
QV qcross(const QV& a, const QV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Exact event time of edge P->Q for eye v0 -> v1 and direction d: -B/A (docs/visibility-math.md
// §2.1).
Q exact_event(Vec3 P, Vec3 Qp, Vec3 v0, Vec3 v1, Vec3 d) {
  QV e = qv(Qp) - qv(P), D = qv(v1) - qv(v0), w = qv(v0) - qv(P), dd = qv(d);
  Q A = qdot(dd, qcross(e, D)), B = qdot(dd, qcross(e, w));
  return -B / A;
}
}  // namespace

TEST(SegmentHardCases, H10_CentimetreTriangleFarFromTheOriginMatchesExactArithmetic) {
  const Vec3 o{1e5, 3e4, -7e4};
  Vec3 v0 = o + Vec3{-0.05, 0, 0}, v1 = o + Vec3{0.07, 0.01, 0};
  std::array<Vec3, 3> t{o + Vec3{-0.005, -0.004, 10}, o + Vec3{0.006, -0.005, 10.001},
                        o + Vec3{0.0005, 0.006, 9.999}};
  Rng rng(3);
  int checked = 0;
  for (int k = 0; k < 200; ++k) {
    Vec3 d{rng.uniform(-0.0065, 0.0065), rng.uniform(-0.0065, 0.0065), 1};
    Cov c = coverage(t, v0, v1, d);
    if (!c.covered) continue;
    // Each end of the interval is 0, 1 or an edge event; compare with the exact event time.
    for (double end : {c.lo, c.hi}) {
      if (end == 0.0 || end == 1.0) continue;
      double best = INFINITY;
      for (int e = 0; e < 3; ++e) {
        Q ex = exact_event(t[e], t[(e + 1) % 3], v0, v1, d);
        best = std::min(best, std::fabs(CGAL::to_double(ex) - end));
      }
      EXPECT_LE(best, 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

namespace {
// Exact sign of a t^2 + b t + c at a double t.
int exact_sign(double a, double b, double c, double t) {
  Q T(t);
  Q v = Q(a) * T * T + Q(b) * T + Q(c);
  return CGAL::sign(v);
}
// The double root r is within `ulps` of an exact sign change of the polynomial.
bool brackets_root(double a, double b, double c, double r, int ulps) {
  double lo = r, hi = r;
  for (int k = 0; k < ulps; ++k) {
    lo = std::nextafter(lo, -INFINITY);
    hi = std::nextafter(hi, INFINITY);
  }
  return exact_sign(a, b, c, lo) * exact_sign(a, b, c, hi) <= 0;
}
}  // namespace

TEST(SegmentHardCases, H11_QuadraticRootsStayAccurateForTinyLeadingCoefficients) {
  double r[2];
  ASSERT_EQ(solve_quadratic(1e-12, 1, -0.5, r), 2);
  double root = std::fabs(r[0] - 0.5) < std::fabs(r[1] - 0.5) ? r[0] : r[1];
  EXPECT_NEAR(root, 0.49999999999975, 1e-15);
  EXPECT_TRUE(brackets_root(1e-12, 1, -0.5, root, 2));
  ASSERT_EQ(solve_quadratic(1e-20, 1, -0.5, r), 2);
  root = std::fabs(r[0] - 0.5) < std::fabs(r[1] - 0.5) ? r[0] : r[1];
  EXPECT_EQ(root, 0.5);
  EXPECT_TRUE(brackets_root(1e-20, 1, -0.5, root, 2));
  ASSERT_EQ(solve_quadratic(1, -1, 0.25 - 1e-12, r), 2);
  // 0.25 - 1e-12 is itself rounded (by up to 2.8e-17); with a discriminant of 4e-12 that moves
  // the true roots of the double input by ~3e-12 from 0.5 -+ 1e-6, so the exact bracketing below
  // is the real check and this one allows 5e-12.
  EXPECT_NEAR(r[0], 0.5 - 1e-6, 5e-12);
  EXPECT_NEAR(r[1], 0.5 + 1e-6, 5e-12);
  EXPECT_TRUE(brackets_root(1, -1, 0.25 - 1e-12, r[0], 64));
  EXPECT_TRUE(brackets_root(1, -1, 0.25 - 1e-12, r[1], 64));
  ASSERT_EQ(solve_quadratic(0, 2, -1, r), 1);
  EXPECT_EQ(r[0], 0.5);
  EXPECT_EQ(solve_quadratic(0, 0, 1, r), 0);
}

// The inline min_num/max_num that replaced std::fmin/std::fmax in the root finder must give the
// same bits as libm for every input the kernel can meet (and NaN), or results change.
TEST(SegmentHardCases, InlineMinAndMaxGiveTheSameBitsAsLibm) {
  auto bits = [](double v) {
    uint64_t b;
    std::memcpy(&b, &v, 8);
    return b;
  };
  const double nan = std::nan("");
  std::vector<double> values = {0.0,     -0.0,     1.0,   -1.0,     0.5,       1e-300,
                                -1e-300, 4.9e-324, 1e300, INFINITY, -INFINITY, nan};
  Rng rng(31);
  for (int k = 0; k < 200; ++k) values.push_back(rng.uniform(-2, 2));
  volatile double sink = 0;  // keeps std::fmin from being folded at compile time
  for (double x : values)
    for (double y : values) {
      volatile double vx = x, vy = y;
      const double lib_min = std::fmin(vx, vy), lib_max = std::fmax(vx, vy);
      sink = lib_min + lib_max;
      const double mn = min_num(x, y), mx = max_num(x, y);
      if (std::isnan(lib_min))
        EXPECT_TRUE(std::isnan(mn)) << x << " " << y;
      else
        EXPECT_EQ(bits(mn), bits(lib_min)) << x << " " << y;
      if (std::isnan(lib_max))
        EXPECT_TRUE(std::isnan(mx)) << x << " " << y;
      else
        EXPECT_EQ(bits(mx), bits(lib_max)) << x << " " << y;
    }
  (void)sink;
}

TEST(SegmentHardCases, H12_FootprintContainsEveryCoveredPixelWhenVerticesAreBehindTheEye) {
  Rng rng(12);
  const int N = 24;
  int covered = 0, missed = 0;
  for (int k = 0; k < 60; ++k) {
    std::array<Vec3, 3> t;
    for (auto& p : t) p = {rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    Vec3 v0{rng.uniform(-.5, .5), rng.uniform(-.5, .5), rng.uniform(-.5, .5)};
    Vec3 v1{rng.uniform(-.5, .5), rng.uniform(-.5, .5), rng.uniform(-.5, .5)};
    Mat3 R = random_orientation(k);
    Vec3 c[3] = {t[0], t[1], t[2]};
    StaticTriangle st = prepare_static_triangle(c, v0, v1);
    Vec3 rel[6] = {t[0] - v0, t[1] - v0, t[2] - v0, t[0] - v1, t[1] - v1, t[2] - v1};
    for (double near : {1e-3, 0.2}) {
      for (int f = 0; f < 6; ++f) {
        FaceAxes ax = face_axes(f, R);
        Footprint fp = compute_footprint(rel, 6, ax, near);
        for (int y = 0; y < N; ++y)
          for (int x = 0; x < N; ++x) {
            double lo, hi;
            LinearDepth dep;
            if (!static_coverage(st, pixel_direction(ax, x, y, N), ax.S, ax.T, near, lo, hi, dep))
              continue;
            ++covered;
            int x0, x1;
            if (!footprint_row_span(fp, N, y, x0, x1) || x < x0 || x > x1) ++missed;
          }
      }
    }
  }
  EXPECT_GT(covered, 2000);
  EXPECT_EQ(missed, 0);
}

TEST(SegmentHardCases, H13_ZeroLengthSegmentEqualsFromPointVisibility) {
  Rng rng(13);
  std::vector<std::array<Vec3, 3>> tris;
  for (int i = 0; i < 25; ++i) {
    Vec3 c{rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-4, 4)};
    std::array<Vec3, 3> t;
    for (auto& p : t) p = c + Vec3{rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)};
    tris.push_back(t);
  }
  Scene s = soup(tris);
  Vec3 v{0.1, -0.2, 0.3};
  SegmentOptions o;
  o.resolution = 32;
  o.near = 0.01;
  o.orientation = random_orientation(13);
  o.want_pieces = true;
  auto r = segment_visibility(s, v, v, o);
  int compared = 0, mismatches = 0;
  for (int f = 0; f < 6; ++f) {
    FaceAxes ax = face_axes(f, o.orientation);
    for (int y = 0; y < o.resolution; ++y)
      for (int x = 0; x < o.resolution; ++x) {
        const PieceList& l = r.pieces[(size_t(f) * o.resolution + y) * o.resolution + x];
        for (const Piece& p : l) {
          EXPECT_EQ(p.t0, 0.0);
          EXPECT_EQ(p.t1, 1.0);
        }
        ASSERT_LE(l.size(), 1u);
        OracleSample ref =
            brute_force_first_hit(s, 0.0, v, pixel_direction(ax, x, y, o.resolution), o.near);
        if (ref.ambiguous) continue;
        ++compared;
        uint32_t ours = l.empty() ? kNoHit : l[0].id;
        if (ours != ref.tri) ++mismatches;
      }
  }
  EXPECT_GT(compared, 5000);
  EXPECT_EQ(mismatches, 0);
}
