// Tests of the near-far partition and the progressive near region (runtime/near_far.h).
#include "runtime/near_far.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

using namespace pvs_runtime;

namespace {

constexpr double kPi = 3.14159265358979323846;

Point3 sub(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
double len(const Point3& a) {
  return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}
double dist(const Point3& a, const Point3& b) {
  return len(sub(a, b));
}
double angle(const Point3& a, const Point3& b) {
  double c = (a.x * b.x + a.y * b.y + a.z * b.z) / (len(a) * len(b));
  return std::acos(std::clamp(c, -1.0, 1.0));
}
// |a x b| / (|a||b|): 0 when parallel.
double sin_angle(const Point3& a, const Point3& b) {
  Point3 c{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return len(c) / (len(a) * len(b));
}

// A range cube map from O filled by ray casting each pixel centre against a caller's surface.
template <class Hit>
std::vector<float> make_range_map(int n, Hit hit) {
  std::vector<float> r(size_t(6) * n * n);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        Point3 d = cube_pixel_direction(f, x, y, n);
        double l = len(d);
        r[(size_t(f) * n + y) * n + x] = float(hit(Point3{d.x / l, d.y / l, d.z / l}));
      }
  return r;
}

const Point3 kO{0, 1.5, 0};
const Point3 kU{2, 1.7, -1};  // the user, inside r1
constexpr double kR1 = 30, kR2 = 50;

}  // namespace

TEST(NearFar, VertexOnR1DoesNotMoveAndJustOutsideBarelyMoves) {
  for (double a : {0.0, 0.7, 2.0, 4.0, 5.5}) {
    for (double y : {0.0, 1.5, 12.0}) {
      Point3 p{kO.x + kR1 * std::cos(a), y, kO.z + kR1 * std::sin(a)};
      Point3 q = morph_vertex(p, kU, kO, kR1, kR2);
      EXPECT_LT(dist(q, p), 1e-12 * kR1) << a << " " << y;
      for (MorphCurve c : {MorphCurve::Linear, MorphCurve::Quadratic, MorphCurve::SCurve}) {
        // 1e-7 beyond r1 the vertex is intermediate, and moves by O(1e-7) only.
        Point3 p2{kO.x + (kR1 + 1e-7) * std::cos(a), y, kO.z + (kR1 + 1e-7) * std::sin(a)};
        EXPECT_EQ(vertex_region(axis_distance(p2, kO), kR1, kR2), Region::Intermediate);
        EXPECT_LT(dist(morph_vertex(p2, kU, kO, kR1, kR2, c), p2), 1e-6) << int(c);
      }
    }
  }
}

// The stationary far region is a wall on the cylinder of radius r2 (range from O analytic per
// pixel). A vertex on r2, placed where a pixel centre ray from O meets the wall, is displaced to
// U + |OP| d_O: on the ray from U parallel to the one from O through P, at the range the map stores
// there, so Eq. 3 keeps it. Approaching r2 from inside (intermediate, Eq. 1) converges to the same.
TEST(NearFar, VertexOnR2LandsOnTheRayFromOAtTheEnvironmentMapRange) {
  const int n = 64;
  auto wall = [](const Point3& d) {
    double h = std::hypot(d.x, d.z);
    return h > 0 ? kR2 / h : std::numeric_limits<double>::infinity();
  };
  std::vector<float> ranges = make_range_map(n, wall);
  RangeCubeMap map{n, ranges.data()};
  int checked = 0;
  for (int f : {0, 1, 4, 5})
    for (int y = 3; y < n; y += 9)
      for (int x = 1; x < n; x += 7) {
        Point3 d = cube_pixel_direction(f, x, y, n);
        double l = len(d);
        Point3 dir{d.x / l, d.y / l, d.z / l};
        double range = wall(dir);
        Point3 p{kO.x + dir.x * range, kO.y + dir.y * range, kO.z + dir.z * range};
        ASSERT_NEAR(axis_distance(p, kO), kR2, 1e-9);
        Point3 q = morph_vertex(p, kU, kO, kR1, kR2);
        Point3 uq = sub(q, kU);
        EXPECT_LT(sin_angle(uq, sub(p, kO)), 1e-12);  // on the ray from U parallel to OP
        EXPECT_GT(uq.x * dir.x + uq.y * dir.y + uq.z * dir.z, 0);  // same way along it
        EXPECT_NEAR(len(uq), cube_range(map, dir), 1e-5 * range);  // at the map's range (a float)
        EXPECT_TRUE(passes_range_test(q, kU, map));
        // From inside the intermediate region, the morph converges to the same point.
        double s = (kR2 - 1e-6) / kR2;
        Point3 p_in{kO.x + (p.x - kO.x) * s, p.y, kO.z + (p.z - kO.z) * s};
        EXPECT_LT(dist(morph_vertex(p_in, kU, kO, kR1, kR2), q), 1e-5);
        ++checked;
      }
  EXPECT_GT(checked, 100);
}

// Eq. 3: a stationary far wall x = 70 (ranges from O) hides a dynamic triangle displaced by Eq. 2
// that stands behind it (x = 90), not one in front of it (x = 60), nor one where the map is empty.
TEST(NearFar, RangeTestHidesADynamicFarTriangleBehindStationaryFarGeometry) {
  const int n = 128;
  auto wall = [](const Point3& d) {
    return d.x > 0 && std::fabs(kO.y + d.y * (70 - kO.x) / d.x) < 40
               ? (70 - kO.x) / d.x
               : std::numeric_limits<double>::infinity();
  };
  std::vector<float> ranges = make_range_map(n, wall);
  RangeCubeMap map{n, ranges.data()};
  auto fragments_passing = [&](double x, double z0) {
    Point3 a{x, 2, z0}, b{x, 8, z0 + 3}, c{x, 1, z0 + 6};
    int pass = 0, total = 0;
    for (int i = 0; i <= 10; ++i)
      for (int j = 0; i + j <= 10; ++j) {  // barycentric samples, vertices included
        double u = i / 10.0, v = j / 10.0, w = 1 - u - v;
        Point3 p{a.x * u + b.x * v + c.x * w, a.y * u + b.y * v + c.y * w,
                 a.z * u + b.z * v + c.z * w};
        EXPECT_EQ(vertex_region(axis_distance(p, kO), kR1, kR2), Region::Far);
        pass += passes_range_test(displace_far(p, kU, kO), kU, map);
        ++total;
      }
    return std::pair<int, int>(pass, total);
  };
  auto behind = fragments_passing(90, -3);
  EXPECT_EQ(behind.first, 0) << "of " << behind.second;
  auto in_front = fragments_passing(60, -3);
  EXPECT_EQ(in_front.first, in_front.second);
  auto on_the_other_side = fragments_passing(-90, -3);  // -X: no stationary geometry
  EXPECT_EQ(on_the_other_side.first, on_the_other_side.second);
}

TEST(NearFar, MorphIsContinuousAlongARadialLine) {
  // Walk a vertex from r = 25 to r = 55 in steps of 1e-3 at several heights and bearings: the
  // displaced point never jumps by more than 50 steps (Lipschitz bound with large margin; a switch
  // between user and environment-map view without the morph jumps by |U - O| > 2).
  const double step = 1e-3;
  for (double a : {0.3, 2.5, 4.4})
    for (double y : {0.0, 6.0}) {
      double worst = 0;
      Point3 prev =
          morph_vertex({kO.x + 25 * std::cos(a), y, kO.z + 25 * std::sin(a)}, kU, kO, kR1, kR2);
      for (double r = 25 + step; r <= 55; r += step) {
        Point3 q =
            morph_vertex({kO.x + r * std::cos(a), y, kO.z + r * std::sin(a)}, kU, kO, kR1, kR2);
        worst = std::max(worst, dist(q, prev));
        prev = q;
      }
      EXPECT_LT(worst, 50 * step) << a << " " << y;
    }
}

TEST(NearFar, PartitionClassifiesByAllVerticesAndPutsTrianglesCrossingR2InBothSets) {
  // Vertices at axis distances 10 (near), 40 (intermediate), 60 and 70 (far), at bearing 0.
  std::vector<float> pos;
  for (double r : {10.0, 40.0, 60.0, 70.0, 11.0, 12.0})
    for (double dy : {0.0, 1.0}) pos.insert(pos.end(), {float(kO.x + r), float(dy), float(kO.z)});
  // v(i, k) = vertex of distance i (0..5), height k.
  auto v = [](uint32_t i, uint32_t k) { return 2 * i + k; };
  std::vector<uint32_t> idx = {
      v(0, 0), v(4, 0), v(5, 1),  // 0: near
      v(0, 0), v(1, 0), v(4, 1),  // 1: intermediate (crosses r1)
      v(1, 0), v(2, 0), v(1, 1),  // 2: crosses r2: intermediate and environment map
      v(2, 0), v(3, 0), v(2, 1),  // 3: far static
      v(2, 1), v(3, 1), v(3, 0),  // 4: far dynamic
      v(1, 0), v(2, 1), v(2, 0),  // 5: crosses r2, dynamic: geometry only
  };
  std::vector<uint8_t> dyn = {0, 0, 0, 0, 1, 1};
  std::vector<uint32_t> ids = {5, 4, 3, 2, 1, 0};
  NearFarPartition p = partition_near_far(pos.data(), pos.size() / 3, idx.data(), 6, dyn.data(),
                                          ids.data(), ids.size(), kO, kR1, kR2);
  EXPECT_EQ(p.near_ids, (std::vector<uint32_t>{0}));
  EXPECT_EQ(p.intermediate_ids, (std::vector<uint32_t>{1, 2, 5}));
  EXPECT_EQ(p.far_static_ids, (std::vector<uint32_t>{3}));
  EXPECT_EQ(p.far_dynamic_ids, (std::vector<uint32_t>{4}));
  EXPECT_EQ(p.environment_map_ids, (std::vector<uint32_t>{2, 3}));
  EXPECT_EQ(p.geometry_ids, (std::vector<uint32_t>{0, 1, 2, 4, 5}));
}

TEST(NearFar, CubePixelOfAPixelCentreIsThatPixel) {
  for (int n : {1, 2, 7, 16})
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          CubePixel p = cube_pixel(cube_pixel_direction(f, x, y, n), n);
          ASSERT_EQ(p.face, f);
          ASSERT_EQ(p.x, x);
          ASSERT_EQ(p.y, y);
        }
}

TEST(NearFar, MorphWeightCurvesAreOneAtR1AndZeroAtR2) {
  for (MorphCurve c : {MorphCurve::Linear, MorphCurve::Quadratic, MorphCurve::SCurve}) {
    EXPECT_EQ(morph_user_weight(kR1, kR1, kR2, c), 1.0);
    EXPECT_EQ(morph_user_weight(kR2, kR1, kR2, c), 0.0);
    EXPECT_NEAR(morph_user_weight(kR1 + 1e-9, kR1, kR2, c), 1.0, 1e-9);
    EXPECT_NEAR(morph_user_weight(kR2 - 1e-9, kR1, kR2, c), 0.0, 1e-9);
  }
  EXPECT_DOUBLE_EQ(morph_user_weight(35, kR1, kR2), 0.75);  // a = r2 - r = 15, / 20
}

// ---- Progressive near region (CloVR) --------------------------------------------------------

TEST(NearFarProgressive, RingRadiiGiveEqualAreasAndIncrease) {
  const double area = 100 * kPi;  // CloVR's 314 m^2: first radius 10 m
  std::vector<double> r = equal_area_ring_radii(area, 63);
  ASSERT_EQ(r.size(), 40u);  // 63^2 / 100 = 39.7 rings
  EXPECT_NEAR(r[0], 10, 1e-12);
  EXPECT_EQ(r.back(), 63);
  double prev = 0;
  for (size_t k = 0; k < r.size(); ++k) {
    ASSERT_GT(r[k], prev);
    double ring = kPi * (r[k] * r[k] - prev * prev);
    if (k + 1 < r.size())
      EXPECT_NEAR(ring, area, 1e-9 * area) << k;
    else
      EXPECT_LE(ring, area * (1 + 1e-12));
    prev = r[k];
  }
  // A final radius on an exact ring boundary gives no sliver ring.
  EXPECT_EQ(equal_area_ring_radii(area, 20).size(), 4u);
}

TEST(NearFarProgressive, RingsMergeUntilEachContributesEnoughAndFarRingsGrowThicker) {
  std::vector<double> r = {1, 2, 3, 4, 5, 6, 7};
  EXPECT_EQ(merge_rings(r, {1, 1, 1, 1, 1, 1, 1}, 2),
            (std::vector<double>{2, 4, 7}));  // 7: short last joins
  EXPECT_EQ(merge_rings(r, {5, 0, 0, 5, 1, 1, 1}, 3), (std::vector<double>{1, 4, 7}));
  EXPECT_EQ(merge_rings(r, {0, 0, 0, 0, 0, 0, 0}, 3), (std::vector<double>{7}));
  // Uniform density, weight 1 / distance (foreshortening): equal-area rings from 10 m to 63 m.
  std::vector<double> radii = equal_area_ring_radii(100 * kPi, 63);
  std::vector<double> item_r, item_w;
  for (double d = 0.0025; d < 63; d += 0.005) {  // thin annuli of uniform density
    item_r.push_back(d);
    item_w.push_back(2 * kPi * d * 0.005 / std::max(d, 1.0));
  }
  std::vector<double> contrib = ring_contributions(radii, item_r, item_w);
  for (size_t k = 1; k < contrib.size() - 1; ++k)
    ASSERT_LE(contrib[k], contrib[k - 1] * (1 + 1e-3)) << k;
  std::vector<double> merged = merge_rings(radii, contrib, contrib[2]);
  ASSERT_GE(merged.size(), 4u);
  EXPECT_NEAR(merged[0], 10, 1e-9);
  // Contributions fall outward, so each merged ring takes at least as many equal-area rings as
  // the one inside it (the last group, which may have absorbed a short remainder, aside).
  std::vector<size_t> group;
  for (double m : merged)
    group.push_back(size_t(std::find(radii.begin(), radii.end(), m) - radii.begin()));
  for (size_t k = 2; k + 1 < group.size(); ++k)
    EXPECT_GE(group[k] - group[k - 1], group[k - 1] - group[k - 2]) << k;
  EXPECT_EQ(group[0], 0u);
  EXPECT_GT(group[group.size() - 2] - group[group.size() - 3], 1u);  // outer rings are merged ones
  std::printf("merged ring radii:");
  for (double m : merged) std::printf(" %.1f", m);
  std::printf("\n");
  EXPECT_EQ(merged.back(), 63);
}

TEST(NearFarProgressive, InjectionWeightIsOneAtRnAndZeroAtR) {
  for (double big_r : {10.0, 14.0, 63.0}) {
    double rn = 0.7 * big_r;
    EXPECT_EQ(injection_weight(rn, big_r, rn), 1.0);
    EXPECT_EQ(injection_weight(big_r, big_r, rn), 0.0);
    EXPECT_EQ(injection_weight(0.0, big_r, rn), 1.0);
    EXPECT_EQ(injection_weight(2 * big_r, big_r, rn), 0.0);
    EXPECT_NEAR(injection_weight(0.85 * big_r, big_r, rn), 0.5, 1e-12);
  }
}

TEST(NearFarProgressive, InjectedVertexStaysAtRnAndFollowsTheEnvironmentMapRayFromR) {
  const Point3 u{1, 1.7, 0.5};
  const double big_r = 20, rn = 14;
  for (double a : {0.1, 1.9, 3.3, 5.0}) {
    Point3 at_rn{kO.x + rn * std::cos(a), 4, kO.z + rn * std::sin(a)};
    EXPECT_LT(dist(inject_vertex(at_rn, u, kO, big_r, rn), at_rn), 1e-12 * big_r);
    for (double r : {big_r, 25.0, 60.0}) {  // on R and beyond: the direction O sees P from
      Point3 p{kO.x + r * std::cos(a), 9, kO.z + r * std::sin(a)};
      Point3 q = inject_vertex(p, u, kO, big_r, rn);
      EXPECT_LT(sin_angle(sub(q, u), sub(p, kO)), 1e-12);
      EXPECT_NEAR(axis_distance(q, kO), r, 1e-9 * r);  // on P's own cylinder
    }
  }
}

// CloVR's growth from R = 14 to 17 m over 300 frames, R_n = 0.7 R, user 1 m beside O: the image
// direction of every vertex of rings around it turns per frame by at most 2 theta dw_max, where
// theta is the angle between d_U and d_O and dw_max = dR / (0.3 R_min) bounds Alg. 1's weight
// change per frame
// (|d angle / dw| <= sin(theta) / cos^2(theta/2) <= 2 theta for theta <= 90 degrees). The discrete
// switch (CloVRD) turns it by theta at once.
TEST(NearFarProgressive, RingGrowthIsContinuous) {
  const Point3 u{kO.x + 1, kO.y, kO.z};
  const double r0 = 14, r1 = 17;
  const int frames = 300;
  const double dr = (r1 - r0) / frames, dw_max = dr / (0.3 * r0);
  double worst_ratio = 0, largest_switch = 0;
  for (double r = 9.5; r <= 20; r += 0.5)
    for (double a : {0.2, 1.6, 3.0, 4.5})
      for (double y : {0.0, 5.0}) {
        Point3 p{kO.x + r * std::cos(a), y, kO.z + r * std::sin(a)};
        double theta = angle(sub(p, u), sub(p, kO));
        largest_switch = std::max(largest_switch, theta);
        Point3 prev = sub(inject_vertex(p, u, kO, r0, 0.7 * r0), u);
        for (int f = 1; f <= frames; ++f) {
          double big_r = r0 + dr * f;
          Point3 cur = sub(inject_vertex(p, u, kO, big_r, 0.7 * big_r), u);
          double turn = angle(prev, cur);
          if (theta > 0) worst_ratio = std::max(worst_ratio, turn / (2 * theta * dw_max));
          prev = cur;
        }
      }
  EXPECT_LE(worst_ratio, 1.0);
  EXPECT_GT(largest_switch, 0.05);  // the jump that the gradual injection avoids is real
  std::printf("worst per-frame turn / bound = %.3f; largest discrete-switch jump %.4f rad\n",
              worst_ratio, largest_switch);
}

TEST(NearFarProgressive, PartitionIsPerObjectAndAnObjectEntersWithItsFirstVertex) {
  // Object 0: triangles 0 (near) and 1 (far); object 1: triangle 2 (far).
  std::vector<float> pos = {1, 0,  0, 2, 0,  0, 1, 1,  0, 30, 0,  0, 31, 0,
                            0, 30, 1, 0, 40, 0, 0, 41, 0, 0,  40, 1, 0};
  std::vector<uint32_t> idx = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  std::vector<uint32_t> obj = {0, 0, 1};
  std::vector<uint32_t> ids = {0, 1, 2};
  ProgressivePartition p = partition_progressive(pos.data(), 9, idx.data(), 3, obj.data(), 2,
                                                 ids.data(), 3, Point3{0, 0, 0}, 10);
  EXPECT_EQ(p.near_ids, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(p.environment_map_ids, (std::vector<uint32_t>{2}));
  std::vector<uint32_t> only_far = {
      1, 2};  // a visible subset: object 0 is near even if triangle 0 is not in it
  p = partition_progressive(pos.data(), 9, idx.data(), 3, obj.data(), 2, only_far.data(), 2,
                            Point3{0, 0, 0}, 10);
  EXPECT_EQ(p.near_ids, (std::vector<uint32_t>{1}));
}
