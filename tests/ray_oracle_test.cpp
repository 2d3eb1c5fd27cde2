#include "tests/support/ray_oracle.h"

#include <gtest/gtest.h>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/eval/embree_scene.h"

using namespace vislib;

namespace {

uint32_t add_triangle(Scene& s, Vec3 a, Vec3 b, Vec3 c) {
  if (s.positions.empty()) s.positions.resize(1);
  auto& p = s.positions[0];
  const uint32_t base = uint32_t(p.size());
  p.push_back(a), p.push_back(b), p.push_back(c);
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangle_object.push_back(0);
  if (s.objects.empty()) s.objects.push_back({"test"});
  return uint32_t(s.triangles.size() - 1);
}

// A big triangle in the plane z = depth covering the +Z axis well inside.
uint32_t add_wall(Scene& s, double depth, double size = 10.0) {
  return add_triangle(s, {-size, -size, depth}, {size, -size, depth}, {0, size, depth});
}

// Face +Z (4) with R = identity; N = 8: pixel (4, 4) has sc = tc = 1/8, d = (1/8, -1/8, 1).
constexpr int kFace = 4, kN = 8, kX = 4, kY = 4;
const Vec3 kDir{0.125, -0.125, 1.0};

}  // namespace

TEST(RayOracle, AgreesWithBruteForceOnSegmentSamples) {
  Scene scene;
  Rng rng(31);
  for (int i = 0; i < 300; ++i) {
    Vec3 c{rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)};
    Vec3 v[3];
    for (auto& q : v)
      q = c + Vec3{rng.uniform(-.8, .8), rng.uniform(-.8, .8), rng.uniform(-.8, .8)};
    add_triangle(scene, v[0], v[1], v[2]);
  }
  const Vec3 v0{-1, -0.5, 0.2}, v1{1.2, 0.7, -0.4};
  const Mat3 R = random_orientation(77);
  const int n = 16;
  const EmbreeScene es(scene, 0.0, v0);
  const RayOracle oracle(es, v0, v1, R, n, 0.05);
  size_t samples = 0, ambiguous = 0, unexplained = 0;
  for (int k = 0; k < 10; ++k) {
    const double t = rng.uniform();
    for (int f = 0; f < kCubeFaces; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          ++samples;
          const OracleSample ref =
              brute_force_first_hit(scene, 0.0, oracle.eye(t), oracle.direction(f, x, y), 0.05);
          if (ref.ambiguous) {
            ++ambiguous;
            continue;
          }
          const Hit h = oracle.first_hit(f, x, y, t);
          if (h.tri == ref.tri) {
            if (h.tri != kNoHit) {
              EXPECT_NEAR(h.lambda, ref.lambda, 1e-5 * ref.lambda);
            }
            continue;
          }
          if (oracle.is_ambiguous(f, x, y, t))
            ++ambiguous;
          else
            ++unexplained;
        }
  }
  EXPECT_EQ(unexplained, 0u);
  EXPECT_LT(double(ambiguous), 0.01 * double(samples)) << ambiguous << " of " << samples;
}

TEST(RayOracle, ClearInteriorHitIsNotAmbiguous) {
  Scene s;
  add_wall(s, 2.0);
  add_wall(s, 3.0);
  const EmbreeScene es(s, 0.0, Vec3{});
  const RayOracle oracle(es, Vec3{}, Vec3{0.1, 0, 0}, Mat3{}, kN, 0.1);
  const OracleSample o = oracle.sample(kFace, kX, kY, 0.5);
  EXPECT_EQ(o.tri, 0u);
  EXPECT_NEAR(o.lambda, 2.0, 1e-6);
  EXPECT_FALSE(o.ambiguous);
  const OracleSample ref = brute_force_first_hit(s, 0.0, oracle.eye(0.5), kDir, 0.1);
  EXPECT_EQ(ref.tri, 0u);
  EXPECT_FALSE(ref.ambiguous);
}

TEST(RayOracle, CoplanarDuplicatesAreAmbiguous) {
  Scene s;
  add_wall(s, 2.0);
  add_wall(s, 2.0);
  const EmbreeScene es(s, 0.0, Vec3{});
  const RayOracle oracle(es, Vec3{}, Vec3{}, Mat3{}, kN, 0.1);
  EXPECT_TRUE(oracle.is_ambiguous(kFace, kX, kY, 0.0));
  const OracleSample ref = brute_force_first_hit(s, 0.0, Vec3{}, kDir, 0.1);
  EXPECT_EQ(ref.tri, 0u);  // exact ties go to the lower id
  EXPECT_TRUE(ref.ambiguous);
}

TEST(RayOracle, NearlyCoplanarIsAmbiguousButSeparatedIsNot) {
  for (double gap : {1e-8, 1e-3}) {
    Scene s;
    add_wall(s, 2.0);
    add_wall(s, 2.0 * (1 + gap));
    const EmbreeScene es(s, 0.0, Vec3{});
    const RayOracle oracle(es, Vec3{}, Vec3{}, Mat3{}, kN, 0.1);
    EXPECT_EQ(oracle.is_ambiguous(kFace, kX, kY, 0.0), gap < kOracleDepthGap) << gap;
    EXPECT_EQ(brute_force_first_hit(s, 0.0, Vec3{}, kDir, 0.1).ambiguous, gap < kReferenceDepthGap)
        << gap;
  }
}

TEST(RayOracle, FirstHitExcludingFindsTheSurfaceBehind) {
  Scene s;
  add_wall(s, 2.0);
  add_wall(s, 5.0);
  const EmbreeScene es(s, 0.0, Vec3{});
  const Hit h = es.first_hit_excluding(Vec3{}, kDir, 0.1, 0);
  EXPECT_EQ(h.tri, 1u);
  EXPECT_NEAR(h.lambda, 5.0, 1e-6);
  EXPECT_EQ(es.first_hit_excluding(Vec3{}, kDir, 0.1, 1).tri, 0u);
}

TEST(RayOracle, RayAlongAnEdgeIsAmbiguous) {
  // The edge x = z/8 of a triangle at depth 2 passes exactly through the pixel ray.
  Scene s;
  add_triangle(s, {0.25, -5, 2}, {0.25, 5, 2}, {5, 0, 2});
  const EmbreeScene es(s, 0.0, Vec3{});
  const RayOracle oracle(es, Vec3{}, Vec3{}, Mat3{}, kN, 0.1);
  EXPECT_TRUE(oracle.is_ambiguous(kFace, kX, kY, 0.0));
  EXPECT_TRUE(brute_force_first_hit(s, 0.0, Vec3{}, kDir, 0.1).ambiguous);
}

TEST(RayOracle, EdgeCrossingThePixelAtThisTimeIsAmbiguous) {
  // Eye moves along +x; the ray of pixel (4,4) meets the edge x = 0.25 at depth 2 when the eye is
  // at x = 0, i.e. t = 0.5 of the segment (-1,0,0) -> (1,0,0).
  Scene s;
  add_triangle(s, {0.25, -5, 2}, {0.25, 5, 2}, {5, 0, 2});
  const EmbreeScene es(s, 0.0, Vec3{-1, 0, 0});
  const RayOracle oracle(es, {-1, 0, 0}, {1, 0, 0}, Mat3{}, kN, 0.1);
  EXPECT_TRUE(oracle.is_ambiguous(kFace, kX, kY, 0.5));
  EXPECT_FALSE(oracle.is_ambiguous(kFace, kX, kY, 0.8));
  EXPECT_EQ(oracle.first_hit(kFace, kX, kY, 0.8).tri, 0u);
  EXPECT_EQ(oracle.first_hit(kFace, kX, kY, 0.2).tri, kNoHit);
}

TEST(RayOracle, HitAtTheNearPlaneIsAmbiguous) {
  Scene s;
  add_wall(s, 0.1 * (1 + 1e-8));
  add_wall(s, 3.0);
  const EmbreeScene es(s, 0.0, Vec3{});
  const RayOracle oracle(es, Vec3{}, Vec3{}, Mat3{}, kN, 0.1);
  EXPECT_TRUE(oracle.is_ambiguous(kFace, kX, kY, 0.0));
  EXPECT_TRUE(brute_force_first_hit(s, 0.0, Vec3{}, kDir, 0.1 * (1 + 1e-8)).ambiguous);
  // Just in front of the near plane: excluded, but still ambiguous.
  const RayOracle closer(es, Vec3{}, Vec3{}, Mat3{}, kN, 0.1 * (1 + 2e-8));
  EXPECT_TRUE(closer.is_ambiguous(kFace, kX, kY, 0.0));
}

TEST(RayOracle, BruteForceNearMissInFrontIsAmbiguous) {
  // Triangle 0 at depth 1 misses the ray by 1e-12 (relative barycentric); triangle 1 behind.
  Scene s;
  const double edge = 0.125 + 1e-12;
  add_triangle(s, {edge, -5, 1}, {edge, 5, 1}, {5, 0, 1});
  add_wall(s, 3.0);
  const OracleSample ref = brute_force_first_hit(s, 0.0, Vec3{}, kDir, 0.1);
  EXPECT_EQ(ref.tri, 1u);
  EXPECT_TRUE(ref.ambiguous);
}

TEST(RayOracle, BruteForceUsesAnimationTime) {
  Scene s;
  add_wall(s, 1.0);
  s.positions.push_back(s.positions[0]);
  for (Vec3& p : s.positions[1]) p.z = 5.0;
  const OracleSample ref = brute_force_first_hit(s, 0.25, Vec3{}, kDir, 0.1);
  EXPECT_EQ(ref.tri, 0u);
  EXPECT_NEAR(ref.lambda, 2.0, 1e-12);
}

// The index must give ray_crossings' list exactly: the same triangles, depths and barycentrics,
// in the same order, for lines that pass through, beside and along triangles of every shape:
// large, tiny, far from the origin, thin, degenerate (collinear corners), and lines parallel to
// the axes (a zero direction component) or running along a triangle's plane.
TEST(RayCrossingIndex, GivesTheBruteForceCrossingsOnEveryLine) {
  Scene s;
  Rng rng(77);
  for (int i = 0; i < 400; ++i) {
    const Vec3 c{rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-50, 50)};
    const double size = i % 4 == 0 ? 1e-4 : i % 4 == 1 ? 40.0 : 2.0;
    const Vec3 a = c + Vec3{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)} * size;
    const Vec3 b = c + Vec3{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)} * size;
    Vec3 d = c + Vec3{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)} * size;
    if (i % 10 == 3) d = a + (b - a) * 0.37;                    // degenerate
    if (i % 10 == 5) d = a + (b - a) * 0.5 + Vec3{0, 1e-7, 0};  // thin
    add_triangle(s, a, b, d);
  }
  add_triangle(s, {1e5, 0, 0}, {1e5 + 1, 0, 0}, {1e5, 1, 0});  // far away
  add_triangle(s, {-3, -3, 7}, {3, -3, 7}, {0, 3, 7});         // axis-aligned plane z = 7
  const RayCrossingIndex index(s, 0);
  size_t lines = 0, crossings = 0;
  auto same = [&](Vec3 eye, Vec3 dir) {
    const std::vector<RayCrossing> want = ray_crossings(s, 0, eye, dir);
    const std::vector<RayCrossing> got = index.crossings(eye, dir);
    ++lines;
    crossings += want.size();
    ASSERT_EQ(got.size(), want.size());
    for (size_t k = 0; k < want.size(); ++k) {
      EXPECT_EQ(got[k].tri, want[k].tri);
      EXPECT_EQ(got[k].lambda, want[k].lambda);
      EXPECT_EQ(got[k].min_bary, want[k].min_bary);
    }
  };
  for (int i = 0; i < 3000; ++i) {
    const Vec3 eye{rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(-60, 60)};
    // Aim at a corner, an edge point or an inner point of a random triangle, or anywhere.
    const auto& t = s.triangles[size_t(rng.uniform(0, double(s.triangle_count()) - 1e-9))];
    const Vec3 p0 = s.positions[0][t[0]], p1 = s.positions[0][t[1]], p2 = s.positions[0][t[2]];
    Vec3 target;
    switch (i % 4) {
      case 0:
        target = p0;
        break;
      case 1:
        target = p0 + (p1 - p0) * rng.uniform();
        break;
      case 2:
        target = (p0 + p1 + p2) * (1.0 / 3.0);
        break;
      default:
        target = {rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(-60, 60)};
    }
    Vec3 dir = target - eye;
    if (i % 7 == 0) dir.x = 0;
    if (i % 11 == 0) dir.y = 0, dir.z = 0, dir.x = 1;
    if (!(length(dir) > 0)) continue;
    same(eye, dir * (1.0 / length(dir)));
  }
  same({-10, 0, 7}, {1, 0, 0});  // along the plane z = 7
  same({0, 0, -20}, {0, 0, 1});  // through the z = 7 triangle, axis-parallel
  EXPECT_GT(crossings, lines / 2) << "the lines must cross triangles for the test to say much";
}
