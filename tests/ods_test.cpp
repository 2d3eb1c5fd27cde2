// Tests of the ODS pure functions (runtime/ods.h): pole merging (Eq. 6), the longitude
// convention, ODS rays, the exact and the paper's (Eq. 5) vertex projection, Alg. 1 / Eq. 4
// tessellation levels, the tessellation and the seam/pole split. Built into runtime_tests, which
// links vislib::runtime alone.
#include "runtime/ods.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

using namespace pvs_runtime;

namespace {

constexpr double kPi = kOdsPi;
constexpr double kDeg = kPi / 180;

PoleMerge symmetric(double start, double end, double exponent) {
  PoleMerge m;
  m.top = m.bottom = PoleMergeSide{start, end, exponent};
  return m;
}

Point3 cross3(const Point3& a, const Point3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double norm3(const Point3& a) {
  return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}
Point3 minus(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}

// ---- Eq. 6 ----

TEST(OdsPoleMerge, FactorIsOneAtStartZeroAtEndAndFollowsTheExponent) {
  const PoleMerge lin = symmetric(45, 0, 1), cubic = symmetric(45, 0, 3);
  EXPECT_EQ(pole_merge_factor(0, lin), 1.0);
  EXPECT_EQ(pole_merge_factor(45 * kDeg, lin), 1.0);  // start: 45 deg from the pole
  EXPECT_EQ(pole_merge_factor(90 * kDeg, lin), 0.0);  // end: at the pole
  EXPECT_EQ(pole_merge_factor(-90 * kDeg, lin), 0.0);
  EXPECT_NEAR(pole_merge_factor(67.5 * kDeg, lin), 0.5, 1e-12);
  EXPECT_NEAR(pole_merge_factor(67.5 * kDeg, cubic), 0.125, 1e-12);
  // end 10 deg from the pole: zero from latitude 80 on.
  const PoleMerge early = symmetric(30, 10, 1);
  EXPECT_EQ(pole_merge_factor(80 * kDeg, early), 0.0);
  EXPECT_EQ(pole_merge_factor(85 * kDeg, early), 0.0);
  EXPECT_NEAR(pole_merge_factor(70 * kDeg, early), 0.5, 1e-12);
}

TEST(OdsPoleMerge, TopAndBottomAreSeparate) {
  PoleMerge m;
  m.top = {45, 0, 1};
  m.bottom = {20, 5, 2};
  EXPECT_NEAR(pole_merge_factor(67.5 * kDeg, m), 0.5, 1e-12);
  EXPECT_EQ(pole_merge_factor(-67.5 * kDeg, m), 1.0);  // bottom starts 20 deg from its pole
  EXPECT_NEAR(pole_merge_factor(-77.5 * kDeg, m), 0.25, 1e-12);
  EXPECT_EQ(pole_merge_factor(-85 * kDeg, m), 0.0);
}

// The paper's "no merging" setting (start = end = 0) makes Eq. 6 read 0/0 at the pole; here it
// is factor 1 everywhere, with no NaN.
TEST(OdsPoleMerge, StartEqualsEndMeansNoMergingWithoutNaN) {
  for (double a : {0.0, 30.0, 90.0}) {
    const PoleMerge m = symmetric(a, a, 1);
    for (double lat = -90; lat <= 90; lat += 0.5) {
      const double f = pole_merge_factor(lat * kDeg, m);
      EXPECT_FALSE(std::isnan(f)) << a << " " << lat;
      EXPECT_EQ(f, 1.0) << a << " " << lat;
    }
  }
  // The paper's literal formula at start = end = 0 and the pole: (90 - 90)/(90 - 90).
  const double merge_start = 90.0 - 0.0, merge_end = 90.0 - 0.0, inclination = 90.0;
  volatile double denominator = merge_end - merge_start;
  EXPECT_TRUE(std::isnan((inclination - merge_start) / denominator));
}

// ---- Alg. 1 line 16 and Eq. 4 ----

TEST(OdsTessellation, Alg1Line16EqualsEq4) {
  for (int k = 0; k <= 6300; ++k) {
    const double max_tess = 1.0 + k * 0.01;
    EXPECT_EQ(std::max(max_tess - 2.0, std::min(max_tess, 3.0)), inner_level_eq4(max_tess))
        << max_tess;
  }
  // Through tessellation_levels: a large triangle near the equator.
  const std::array<LonLat, 3> v{LonLat{0, 0}, LonLat{60 * kDeg, 0}, LonLat{30 * kDeg, 30 * kDeg}};
  const std::array<LonLat, 3> mid{LonLat{45 * kDeg, 16 * kDeg}, LonLat{15 * kDeg, 16 * kDeg},
                                  LonLat{30 * kDeg, 0}};
  const TessLevels t = tessellation_levels(v, mid);
  const double mx = std::max({t.outer[0], t.outer[1], t.outer[2]});
  EXPECT_EQ(t.inner, inner_level_eq4(mx));
  // Edge 2 (v0-v1): 60 deg of longitude, max latitude 0: 0.125 * 60 = 7.5.
  EXPECT_NEAR(t.outer[2], 7.5, 1e-12);
}

TEST(OdsTessellation, EdgeLevelFollowsAlg1AndIsSymmetric) {
  // 16 deg long edge at latitude 0: d = 2, no pole multiplier.
  EXPECT_NEAR(edge_outer_level({0, 0}, {16 * kDeg, 0}, {8 * kDeg, 0}), 2.0, 1e-12);
  // At latitude 60: pole multiplier 2.8284/90 * 60.
  const double l = edge_outer_level({0, 60 * kDeg}, {16 * kDeg, 60 * kDeg}, {8 * kDeg, 61 * kDeg});
  EXPECT_NEAR(l, 2.8284 / 90 * 61 * 0.125 * std::hypot(16.0, 0.5), 1e-9);
  EXPECT_EQ(l, edge_outer_level({16 * kDeg, 60 * kDeg}, {0, 60 * kDeg}, {8 * kDeg, 61 * kDeg}));
  // Capped at 64; across the seam the short way (footnote: lonDist(-170, 165) = 25).
  EXPECT_EQ(edge_outer_level({0, 80 * kDeg}, {179 * kDeg, -80 * kDeg}, {90 * kDeg, 89 * kDeg}),
            64.0);
  EXPECT_DOUBLE_EQ(lon_dist_deg(-170, 165), 25.0);
  EXPECT_NEAR(edge_outer_level({-170 * kDeg, 0}, {165 * kDeg, 0}, {177.5 * kDeg, 0}), 25 * 0.125,
              1e-12);
}

// Sum of the signed areas (barycentric plane) of the tessellation's triangles.
double covered_area(const Tessellation& t, bool* all_positive) {
  double sum = 0;
  *all_positive = true;
  for (const auto& tri : t.triangles) {
    const auto &a = t.points[tri[0]], &b = t.points[tri[1]], &c = t.points[tri[2]];
    const double area = 0.5 * ((b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]));
    if (!(area > 0)) *all_positive = false;
    sum += area;
  }
  return sum;
}

TEST(OdsTessellation, CoversTheTriangleOnceWithPositiveOrientation) {
  for (auto levels : std::vector<std::array<int, 4>>{{1, 1, 1, 1},
                                                     {4, 4, 4, 4},
                                                     {16, 16, 16, 16},
                                                     {1, 7, 3, 5},
                                                     {64, 1, 2, 62},
                                                     {5, 5, 9, 3}}) {
    const Tessellation t = tessellate_triangle({levels[0], levels[1], levels[2]}, levels[3]);
    bool positive = false;
    EXPECT_NEAR(covered_area(t, &positive), 0.5, 1e-12);
    EXPECT_TRUE(positive);
    const int n = std::max({levels[0], levels[1], levels[2], levels[3]});
    EXPECT_LE(t.triangles.size(), size_t(n) * n);
  }
  EXPECT_EQ(tessellate_triangle({4, 4, 4}, 4).triangles.size(), 16u);
}

// The points on edge i are exactly outer[i] + 1 equally spaced ones whatever the other levels, so
// two triangles sharing an edge at the same level meet without a crack.
TEST(OdsTessellation, SharedEdgeHasTheSameBoundaryPointsWhateverTheOtherLevels) {
  auto edge0_params = [](const Tessellation& t) {
    std::set<double> s;
    for (const auto& p : t.points)
      if (p[0] == 0) s.insert(p[2]);
    return s;
  };
  const auto a = edge0_params(tessellate_triangle({5, 1, 1}, 1));
  const auto b = edge0_params(tessellate_triangle({5, 17, 40}, 38));
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 6u);
  // Seen from the neighbour, the same edge runs the other way: its weights are the same rationals.
  for (double w : a) EXPECT_TRUE(a.count(double(5 - int(std::lround(w * 5))) / 5)) << w;
}

// ---- Longitude convention ----

TEST(OdsLongitude, AllFourQuadrantsFollowMinusAtan2) {
  auto lon = [](double x, double z) { return direction_lonlat({x, 0, z}).lon / kDeg; };
  EXPECT_NEAR(lon(0, 1), 0, 1e-12);
  EXPECT_NEAR(lon(1, 0), -90, 1e-12);  // Eq. 2's z = 0, x >= 0 branch
  EXPECT_NEAR(lon(-1, 0), 90, 1e-12);  // Eq. 2's z = 0, x < 0 branch
  EXPECT_NEAR(lon(1, 1), -45, 1e-12);
  EXPECT_NEAR(lon(-1, 1), 45, 1e-12);
  EXPECT_NEAR(lon(-1, -1), 135, 1e-12);  // z < 0: the branch Eq. 2 lacks
  EXPECT_NEAR(lon(1, -1), -135, 1e-12);
  EXPECT_NEAR(lon(0, -1), 180, 1e-12);  // the seam maps to +180, not -180
  // Round trip through the direction.
  for (double lo = -179; lo <= 180; lo += 7)
    for (double la = -85; la <= 85; la += 17) {
      const LonLat back = direction_lonlat(lonlat_direction({lo * kDeg, la * kDeg}));
      EXPECT_NEAR(back.lon / kDeg, lo, 1e-9);
      EXPECT_NEAR(back.lat / kDeg, la, 1e-9);
    }
  // Increasing longitude turns right: right of +z with y up is -x.
  EXPECT_LT(lonlat_direction({10 * kDeg, 0}).x, 0);
}

TEST(OdsLongitude, PixelCentresAndTheSeam) {
  const int w = 512, h = 256;
  const LonLat first = pixel_to_lonlat(0.5, 0.5, w, h),
               last = pixel_to_lonlat(w - 0.5, h - 0.5, w, h);
  EXPECT_NEAR(first.lon, -kPi + kPi / w, 1e-15);
  EXPECT_NEAR(first.lat, kPi / 2 - kPi / (2 * h), 1e-15);  // y up: row 0 at the top
  EXPECT_NEAR(last.lon, kPi - kPi / w, 1e-15);
  // Columns 0 and W-1 are neighbours across the seam: one pixel apart the short way.
  EXPECT_NEAR(std::fabs(wrap_longitude(last.lon - first.lon)), 2 * kPi / w, 1e-12);
  const auto px = lonlat_to_pixel({0, 0}, w, h);
  EXPECT_DOUBLE_EQ(px[0], w / 2.0);
  EXPECT_DOUBLE_EQ(px[1], h / 2.0);
  // The pixel ray of column x, row y has the pixel centre's direction.
  const Ray r = ods_pixel_ray(0, 0, w, h, {0, 0, 0}, 0, Eye::Left, {});
  const LonLat rl = direction_lonlat(r.direction);
  EXPECT_NEAR(rl.lon, first.lon, 1e-12);
  EXPECT_NEAR(rl.lat, first.lat, 1e-12);
  EXPECT_NEAR(wrap_longitude(kPi), kPi, 0);
  EXPECT_NEAR(wrap_longitude(-kPi), kPi, 0);
  EXPECT_NEAR(wrap_longitude(3 * kPi / 2), -kPi / 2, 1e-15);
}

// ---- Rays and projections ----

TEST(OdsRay, OriginIsOnTheViewingCircleAndTangent) {
  const Point3 c{3, 1.6, -2};
  for (Eye eye : {Eye::Left, Eye::Right})
    for (double lo = -180; lo < 180; lo += 30) {
      const Ray r = ods_ray({lo * kDeg, 20 * kDeg}, c, 0.064, eye, {});
      const Point3 o = minus(r.origin, c);
      EXPECT_NEAR(std::hypot(o.x, o.z), 0.032, 1e-15);
      EXPECT_EQ(o.y, 0);
      EXPECT_NEAR(o.x * r.direction.x + o.z * r.direction.z, 0, 1e-15);  // tangent
      // The right eye sits on the viewer's right: right = forward x up.
      const Point3 right = cross3({r.direction.x, 0, r.direction.z}, {0, 1, 0});
      EXPECT_GT(double(int(eye)) * (o.x * right.x + o.z * right.z), 0);
    }
}

TEST(OdsProjection, ExactProjectionThenPixelRayPassesThroughThePoint) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-1, 1), logd(std::log(0.05), std::log(1e4));
  const Point3 c{1e5, 2.5, -3e4};  // far from the origin: the formulas work relative to C
  int checked = 0;
  for (const PoleMerge& m : {PoleMerge{}, symmetric(45, 0, 1), symmetric(60, 10, 3)})
    for (int k = 0; k < 4000; ++k) {
      Point3 d{u(rng), u(rng), u(rng)};
      const double s = std::exp(logd(rng)) / norm3(d);
      const Point3 p{c.x + d.x * s, c.y + d.y * s, c.z + d.z * s};
      for (Eye eye : {Eye::Left, Eye::Right}) {
        const OdsProjection pr = ods_project_exact(p, c, 0.064, eye, m);
        if (!pr.visible) continue;
        const Ray r = ods_ray(pr.ll, c, 0.064, eye, m);
        const Point3 op = minus(p, r.origin);
        const double dist = norm3(op);
        EXPECT_LE(norm3(cross3(op, r.direction)), 1e-9 * dist) << k;  // on the ray's line
        EXPECT_GT(op.x * r.direction.x + op.y * r.direction.y + op.z * r.direction.z, 0);  // ahead
        EXPECT_NEAR(pr.range, dist, 1e-9 * dist);
        ++checked;
      }
    }
  EXPECT_GT(checked, 20000);
}

TEST(OdsProjection, PointsInsideTheViewingCircleAreNotVisibleButEq5PlacesThem) {
  const Point3 c{0, 0, 0};
  for (double r : {0.0, 0.01, 0.031999})
    for (double y : {-1.0, 0.0, 2.0}) {
      if (r == 0 && y == 0) continue;
      const Point3 p{r, y, 0};
      EXPECT_FALSE(ods_project_exact(p, c, 0.064, Eye::Left, {}).visible) << r << " " << y;
      const OdsProjection paper = ods_project_paper(p, c, 0.064, Eye::Left, {});
      EXPECT_TRUE(paper.visible);
      EXPECT_TRUE(std::isfinite(paper.ll.lon) && std::isfinite(paper.ll.lat));
    }
  EXPECT_TRUE(ods_project_exact({0.0321, 0, 0}, c, 0.064, Eye::Left, {}).visible);
  // With merging down to 0 at the pole, a point straight above is visible at the pole row.
  const OdsProjection up = ods_project_exact({0, 3, 0}, c, 0.064, Eye::Right, symmetric(45, 0, 1));
  EXPECT_TRUE(up.visible);
  EXPECT_DOUBLE_EQ(up.ll.lat, kPi / 2);
}

TEST(OdsProjection, Eq5IsGuardedStraightUpAndDown) {
  for (double y : {1.0, -1.0}) {
    const OdsProjection p = ods_project_paper({0, y, 0}, {0, 0, 0}, 0.064, Eye::Right, {});
    EXPECT_FALSE(std::isnan(p.ll.lon) || std::isnan(p.ll.lat));
    EXPECT_DOUBLE_EQ(p.ll.lat, y * kPi / 2);
    EXPECT_DOUBLE_EQ(p.range, 1.0);
  }
}

TEST(OdsProjection, IpdZeroGivesTheMonoProjectionForBothEyes) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int k = 0; k < 1000; ++k) {
    const Point3 p{u(rng), u(rng), u(rng)};
    const LonLat mono = direction_lonlat(p);
    for (Eye eye : {Eye::Left, Eye::Right}) {
      const OdsProjection e = ods_project_exact(p, {0, 0, 0}, 0.0, eye, symmetric(45, 0, 1));
      ASSERT_TRUE(e.visible);
      EXPECT_EQ(e.ll.lon, mono.lon);
      EXPECT_NEAR(e.ll.lat, mono.lat, 1e-15);
    }
  }
  const Ray r = ods_ray({0.3, 0.2}, {1, 2, 3}, 0, Eye::Left, {});
  EXPECT_EQ(r.origin.x, 1);
  EXPECT_EQ(r.origin.z, 3);
}

// The paper's Eq. 5 against the exact tangent ray, 3840 px wide (10.67 px a degree both ways),
// IPD 6.4 cm. On the equator only the longitude differs: atan vs asin of h/r_h, 0.08 px at
// r_h = 0.5 m, 1.24 px at 0.2 m, 9.8 px at 0.1 m (about 10 px at 0.1 m). Off the
// equator the latitude differs too (sqrt(r_h^2 + h^2) vs sqrt(r_h^2 - h^2)), worst near 45 deg:
// 1.25 px at 0.5 m (about 1 px), 7.9 px at 0.2 m (more than the 3 px one might expect) and 33 px at
// 0.1 m.
TEST(OdsProjection, Eq5ErrorAgainstTheTangentRayInPixels) {
  const double px_per_rad = 3840 / (2 * kPi), h = 0.032;
  auto error_px = [&](double rh, double elevation_deg) {
    const Point3 p{0, rh * std::tan(elevation_deg * kDeg), rh};
    const OdsProjection e = ods_project_exact(p, {0, 0, 0}, 2 * h, Eye::Right, {});
    const OdsProjection q = ods_project_paper(p, {0, 0, 0}, 2 * h, Eye::Right, {});
    return std::hypot(wrap_longitude(e.ll.lon - q.ll.lon), e.ll.lat - q.ll.lat) * px_per_rad;
  };
  EXPECT_NEAR(error_px(0.5, 0), 0.080, 0.002);
  EXPECT_NEAR(error_px(0.2, 0), 1.244, 0.002);
  EXPECT_NEAR(error_px(0.1, 0), 9.795, 0.002);
  EXPECT_NEAR(error_px(0.5, 45), 1.254, 0.002);
  EXPECT_NEAR(error_px(0.2, 45), 7.923, 0.002);
  EXPECT_NEAR(error_px(0.1, 45), 32.88, 0.01);
  EXPECT_LT(error_px(10, 45), 0.01);
  // The closed form: the longitude offset is asin(h/r_h) exactly.
  const OdsProjection e = ods_project_exact({0, 0, 0.1}, {0, 0, 0}, 2 * h, Eye::Right, {});
  EXPECT_NEAR(e.ll.lon, -std::asin(h / 0.1), 1e-15);
}

// With merging, the latitude is a fixed point. Three steps from the h = 0 latitude bring it
// within 1e-9 rad (1e-6 px at 3840 wide) at r_h >= 0.5 m; the function iterates on to 1e-15 rad,
// which takes up to 6 steps here.
TEST(OdsProjection, PoleMergedFixedPointConvergesInFewSteps) {
  const PoleMerge m = symmetric(60, 0, 1);
  int worst = 0;
  double worst_after3 = 0;
  for (double rh : {0.5, 1.0, 5.0, 50.0})
    for (double el = -85; el <= 85; el += 5) {
      const Point3 p{rh * 0.6, rh * std::tan(el * kDeg), rh * 0.8};
      const OdsProjection e = ods_project_exact(p, {0, 0, 0}, 0.064, Eye::Left, m);
      ASSERT_TRUE(e.visible);
      worst = std::max(worst, e.iterations);
      EXPECT_NEAR(e.h, 0.032 * pole_merge_factor(e.ll.lat, m), 1e-18);
      // The iteration written out here: lat <- atan2(dy, sqrt(r_h^2 - h(lat)^2)).
      double lat = std::atan2(p.y, rh);
      for (int k = 0; k < 3; ++k) {
        const double h = 0.032 * pole_merge_factor(lat, m);
        lat = std::atan2(p.y, std::sqrt(rh * rh - h * h));
      }
      worst_after3 = std::max(worst_after3, std::fabs(lat - e.ll.lat));
    }
  EXPECT_LE(worst_after3, 1e-9);
  EXPECT_LE(worst, 8);
  // Near the viewing circle, where the fixed point converges slowly, bisection still solves it.
  const OdsProjection near = ods_project_exact({0.0325, 0.05, 0}, {0, 0, 0}, 0.064, Eye::Left, m);
  if (near.visible) {
    const Ray r = ods_ray(near.ll, {0, 0, 0}, 0.064, Eye::Left, m);
    const Point3 op = minus({0.0325, 0.05, 0}, r.origin);
    EXPECT_LE(norm3(cross3(op, r.direction)), 1e-9 * norm3(op));
  }
}

// ---- Seam and pole split ----

TEST(OdsSplit, PaperSeamExampleIsDrawnOnBothSides) {
  // §3.2: vertices at (-170, 45), (-170, 35), (165, 40): 25 deg wide across the back.
  const std::array<ProjVertex, 3> v{ProjVertex{-170 * kDeg, 45 * kDeg, 1, -170 * kDeg},
                                    ProjVertex{-170 * kDeg, 35 * kDeg, 1, -170 * kDeg},
                                    ProjVertex{165 * kDeg, 40 * kDeg, 1, 165 * kDeg}};
  const auto out = split_seam_pole(v, 0, 0);
  ASSERT_EQ(out.size(), 2u);
  for (const ProjTriangle& t : out) {
    const double lo = std::min({t.v[0].lon, t.v[1].lon, t.v[2].lon});
    const double hi = std::max({t.v[0].lon, t.v[1].lon, t.v[2].lon});
    EXPECT_NEAR((hi - lo) / kDeg, 25, 1e-9);  // never the 335 deg wide wrong triangle
    EXPECT_TRUE(lo < -kPi || hi > kPi);
  }
  // A triangle away from the seam is drawn once, unchanged.
  const std::array<ProjVertex, 3> w{ProjVertex{0, 0, 1}, ProjVertex{0.1, 0, 1, 0.1},
                                    ProjVertex{0, 0.1, 1, 0}};
  EXPECT_EQ(split_seam_pole(w, 0, 0).size(), 1u);
}

// Near the axis the eye offsets (up to 90 deg) differ between the vertices of one triangle, and
// the short way between eye longitudes goes round the wrong side: unwrap by centre longitudes.
TEST(OdsSplit, UnwrapsByCentreLongitudeNotByEyeLongitude) {
  const std::array<ProjVertex, 3> v{ProjVertex{-85 * kDeg, -80 * kDeg, 1, 0},
                                    ProjVertex{165 * kDeg, -80 * kDeg, 1, 170 * kDeg},
                                    ProjVertex{20 * kDeg, -85 * kDeg, 1, 50 * kDeg}};
  const auto out = split_seam_pole(v, 0, 0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].v[1].lon / kDeg, 165, 1e-9);  // not 165 - 360
  EXPECT_NEAR(out[0].v[2].lon / kDeg, 20, 1e-9);
}

TEST(OdsSplit, PoleComesFromTheAxisCrossingNotTheFirstVertex) {
  // First vertex high above the centre, but the triangle crosses the axis below it.
  const std::array<Point3, 3> v{Point3{1, 5, 0.2}, Point3{-1, -4, 1}, Point3{-0.2, -4, -1}};
  const AxisCrossing a = axis_crossing(v, {0, 0, 0});
  ASSERT_TRUE(a.crosses);
  EXPECT_LT(a.point.y, 0);
  EXPECT_EQ(a.pole, -1);
  EXPECT_NEAR(a.bary[0] + a.bary[1] + a.bary[2], 1, 1e-15);
  // A triangle off the axis does not cross; a vertical one never does.
  EXPECT_FALSE(
      axis_crossing({Point3{1, 0, 1}, Point3{2, 0, 1}, Point3{1, 0, 2}}, {0, 0, 0}).crosses);
  EXPECT_FALSE(
      axis_crossing({Point3{0, 0, 0}, Point3{0, 1, 0}, Point3{1, 0, 0}}, {0, 0.5, 0}).crosses);
}

TEST(OdsSplit, PoleTriangleBecomesAStripToThePoleRow) {
  // Three vertices around the north pole at 60 deg latitude.
  const std::array<ProjVertex, 3> v{ProjVertex{-150 * kDeg, 60 * kDeg, 2, -150 * kDeg},
                                    ProjVertex{-30 * kDeg, 60 * kDeg, 2, -30 * kDeg},
                                    ProjVertex{90 * kDeg, 60 * kDeg, 2, 90 * kDeg}};
  const auto out = split_seam_pole(v, 1, 1.5);
  // 3 quads of 2 triangles, the one across the seam (90 -> 210) twice.
  EXPECT_EQ(out.size(), 8u);
  double covered = 0;  // lon extent of the strip at the pole row, without the shifted copies
  for (const ProjTriangle& t : out) {
    for (const ProjVertex& p : t.v) {
      if (p.lat == kPi / 2) {
        EXPECT_EQ(p.range, 1.5);
      }
    }
  }
  for (size_t i = 0; i < out.size(); ++i) {
    const auto& t = out[i];
    if (t.v[2].lat == kPi / 2 && t.v[0].lat != kPi / 2)
      covered += std::fabs(t.v[1].lon - t.v[0].lon);
  }
  EXPECT_GE(covered / kDeg, 360 - 1e-9);  // the strip spans every longitude
}

}  // namespace
