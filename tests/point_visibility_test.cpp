#include "vislib/eval/point_visibility.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <stdexcept>

#include "tests/support/ray_oracle.h"
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

// `count` random triangles with centres in [-half, half]^3 and edges up to `size`.
Scene random_soup(int count, uint64_t seed, double half = 5.0, double size = 1.5) {
  Scene s;
  Rng rng(seed);
  for (int i = 0; i < count; ++i) {
    Vec3 c{rng.uniform(-half, half), rng.uniform(-half, half), rng.uniform(-half, half)};
    Vec3 v[3];
    for (auto& q : v)
      q = c +
          Vec3{rng.uniform(-size, size), rng.uniform(-size, size), rng.uniform(-size, size)} * 0.5;
    add_triangle(s, v[0], v[1], v[2]);
  }
  return s;
}

// A triangle of half-size h around c, in the plane through c orthogonal to the world axis `axis`.
uint32_t add_small_triangle(Scene& s, Vec3 c, int axis, double h) {
  Vec3 u, w;
  u[(axis + 1) % 3] = h;
  w[(axis + 2) % 3] = h;
  return add_triangle(s, c - u - w, c + u - w, c + w);
}

size_t pixel(int face, int x, int y, int n) {
  return (size_t(face) * n + y) * n + x;
}

}  // namespace

TEST(PointVisibility, MatchesBruteForceOnRandomSoupExceptAmbiguousPixels) {
  const Scene scene = random_soup(300, 7);
  const int n = 32;
  const double z_near = 0.05;
  size_t pixels = 0, ambiguous = 0, unexplained = 0;
  for (uint64_t view = 0; view < 3; ++view) {
    Rng rng(Rng::derive(99, view));
    const Vec3 eye{rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    const Mat3 R = random_orientation(Rng::derive(5, view));
    const EmbreeScene es(scene, 0.0, eye);
    const RayOracle oracle(es, eye, eye, R, n, z_near);
    const auto cube = point_cubemap(es, eye, R, n, z_near);
    for (int f = 0; f < kCubeFaces; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          ++pixels;
          const Vec3 d = pixel_direction(face_axes(f, R), x, y, n);
          const OracleSample ref = brute_force_first_hit(scene, 0.0, eye, d, z_near);
          if (ref.ambiguous) {
            ++ambiguous;
            continue;
          }
          if (cube[pixel(f, x, y, n)] == ref.tri) continue;
          if (oracle.is_ambiguous(f, x, y, 0.0))
            ++ambiguous;
          else
            ++unexplained;
        }
  }
  EXPECT_EQ(unexplained, 0u);
  EXPECT_LT(double(ambiguous), 0.01 * double(pixels)) << ambiguous << " of " << pixels;
}

TEST(PointVisibility, CubemapConventionPutsTriangleAtTheTablePixel) {
  const int n = 16, x = 3, y = 11;
  const double sc = pixel_center(x, n), tc = pixel_center(y, n);
  struct Case {
    int face;
    Vec3 d;  // the binding table of cubemap.h / docs/visibility-math.md §1, written out by hand
    int axis;
  };
  const Case cases[] = {{0, {1, -tc, -sc}, 0}, {5, {-sc, -tc, -1}, 2}, {2, {sc, 1, tc}, 1}};
  Mat3 rot_z;  // 90 degrees about +Z: local +X -> world +Y
  rot_z.m[0] = 0, rot_z.m[1] = -1, rot_z.m[3] = 1, rot_z.m[4] = 0;
  for (const Mat3& R : {identity_orientation(), rot_z})
    for (const Case& c : cases) {
      const Vec3 eye{1, 2, 3}, world_d = R * c.d;
      int axis = 0;  // world axis the face looks along
      for (int k = 1; k < 3; ++k)
        if (std::fabs(world_d[k]) > std::fabs(world_d[axis])) axis = k;
      Scene s;
      // Depth 5 along d: a pixel spans 10/n there; the triangle is a fifth of that.
      add_small_triangle(s, eye + world_d * 5.0, axis, 0.2 * 10.0 / n);
      const EmbreeScene es(s, 0.0, eye);
      const auto cube = point_cubemap(es, eye, R, n, 0.1);
      for (size_t i = 0; i < cube.size(); ++i)
        EXPECT_EQ(cube[i], i == pixel(c.face, x, y, n) ? 0u : kNoHit)
            << "face " << c.face << " pixel index " << i;
    }
}

TEST(PointVisibility, HitCloserThanNearIsIgnored) {
  Scene s;
  const Vec3 eye{0, 0, 0};
  // id 0: small, at depth 0.05 on +Z (too small to reach lambda > 0.1 on the side faces)
  add_triangle(s, {-0.02, -0.02, 0.05}, {0.02, -0.02, 0.05}, {0, 0.02, 0.05});
  add_triangle(s, {-1, -1, 2.0}, {1, -1, 2.0}, {0, 1, 2.0});  // id 1, depth 2
  const EmbreeScene es(s, 0.0, eye);
  const int n = 8;
  const Mat3 R;
  EXPECT_EQ(point_cubemap(es, eye, R, n, 0.1)[pixel(4, 4, 4, n)], 1u);
  EXPECT_EQ(point_cubemap(es, eye, R, n, 0.01)[pixel(4, 4, 4, n)], 0u);
  const Hit h = es.first_hit(eye, pixel_direction(face_axes(4, R), 4, 4, n), 0.1);
  EXPECT_EQ(h.tri, 1u);
  EXPECT_NEAR(h.lambda, 2.0, 1e-6);  // lambda is the view depth along the un-normalised d
  EXPECT_EQ(point_visible_set(es, eye, R, n, 0.1), (std::vector<uint32_t>{1}));
}

TEST(PointVisibility, SameCubemapWithOneAndTwoThreads) {
  const Scene scene = random_soup(3000, 11, 10.0, 2.0);
  const Vec3 eye{0.3, -0.2, 0.1};
  const Mat3 R = random_orientation(3);
  std::vector<uint32_t> cube[2];
  for (int threads = 1; threads <= 2; ++threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const EmbreeScene es(scene, 0.0, eye);  // the BVH build too runs under the limit
    cube[threads - 1] = point_cubemap(es, eye, R, 64, 0.05);
  }
  EXPECT_EQ(cube[0], cube[1]);
}

TEST(PointVisibility, CubemapEqualsSingleRayCasts) {
  // point_cubemap uses Embree's coherent ray stream; the oracle uses single rays.
  const Scene scene = random_soup(3000, 12, 10.0, 2.0);
  const Vec3 eye{0.3, -0.2, 0.1};
  const EmbreeScene es(scene, 0.0, Vec3{1, 1, 1});
  const int n = 64;
  size_t hits = 0;
  for (uint64_t seed = 0; seed < 3; ++seed) {
    const Mat3 R = random_orientation(seed);
    const auto cube = point_cubemap(es, eye, R, n, 0.05);
    const RayOracle oracle(es, eye, eye, R, n, 0.05);
    for (int f = 0; f < kCubeFaces; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const uint32_t single = oracle.first_hit(f, x, y, 0.0).tri;
          // Stream and single-ray kernels may differ only on marginal (ambiguous) rays.
          if (cube[pixel(f, x, y, n)] != single) {
            EXPECT_TRUE(oracle.is_ambiguous(f, x, y, 0.0)) << f << " " << x << " " << y;
          }
          hits += single != kNoHit;
        }
  }
  EXPECT_GT(hits, 0u);
}

TEST(PointVisibility, BigCoordinatesStillHitCentimetreTriangle) {
  const Vec3 eye{1e5 + 0.123, -1e5 + 0.456, 1e5 + 0.789};
  const int n = 64, x = 20, y = 40;
  const double sc = pixel_center(x, n), tc = pixel_center(y, n);
  const Vec3 d{1, -tc, -sc};  // face +X
  Scene s;
  add_small_triangle(s, eye + d * 2.0, 0, 0.005);  // 1 cm across, 2 m away
  const EmbreeScene es(s, 0.0, eye);
  const auto cube = point_cubemap(es, eye, Mat3{}, n, 0.1);
  for (size_t i = 0; i < cube.size(); ++i) EXPECT_EQ(cube[i], i == pixel(0, x, y, n) ? 0u : kNoHit);
  EXPECT_NEAR(es.first_hit(eye, d, 0.1).lambda, 2.0, 1e-6);
}

TEST(PointVisibility, SegmentSamplingUnionGrowsAndEqualsUnionOfPointSets) {
  const Scene scene = random_soup(500, 21);
  const Vec3 v0{-2, 0, 0}, v1{2, 1, 0};
  const EmbreeScene es(scene, 0.0, v0);
  PointSampling opt;
  opt.runs = 5;
  opt.n = 32;
  opt.z_near = 0.05;
  opt.random_orientation = true;
  opt.seed = 4;
  const SampledVisibility sv = sample_segment(es, v0, v1, opt);
  ASSERT_EQ(sv.union_size.size(), 5u);
  ASSERT_EQ(sv.elapsed_seconds.size(), 5u);
  EXPECT_TRUE(std::is_sorted(sv.union_size.begin(), sv.union_size.end()));
  EXPECT_TRUE(std::is_sorted(sv.elapsed_seconds.begin(), sv.elapsed_seconds.end()));
  EXPECT_EQ(sv.union_size.back(), sv.ids.size());
  EXPECT_EQ(sv.viewpoints.front(), v0);
  EXPECT_EQ(sv.viewpoints.back(), v1);
  std::vector<uint32_t> expect;
  for (int i = 0; i < 5; ++i) {
    auto set =
        point_visible_set(es, sv.viewpoints[i], random_orientation(Rng::derive(4, i)), 32, 0.05);
    expect.insert(expect.end(), set.begin(), set.end());
  }
  EXPECT_EQ(sv.ids, visible_set(expect));
}

TEST(PointVisibility, BoxSamplingIsReproducibleBySeedAndStaysInTheBox) {
  const Scene scene = random_soup(500, 22);
  const EmbreeScene es(scene, 0.0, Vec3{});
  Box3 box;
  box.extend({-1, -1, -1});
  box.extend({1, 2, 1});
  PointSampling opt;
  opt.runs = 4;
  opt.n = 16;
  opt.seed = 8;
  const SampledVisibility a = sample_box(es, box, opt), b = sample_box(es, box, opt);
  EXPECT_EQ(a.ids, b.ids);
  EXPECT_EQ(a.union_size, b.union_size);
  for (const Vec3& p : a.viewpoints)
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(p[k], box.min[k]);
      EXPECT_LE(p[k], box.max[k]);
    }
  opt.seed = 9;
  EXPECT_NE(sample_box(es, box, opt).viewpoints[0], a.viewpoints[0]);
}

TEST(EmbreeScene, BadDeviceConfigThrows) {
  Scene s;
  EXPECT_THROW(EmbreeScene(s, 0.0, Vec3{}, "threads=notanumber,bogus=1"), std::runtime_error);
}

TEST(EmbreeScene, BuildsAtAnimationTime) {
  Scene s;
  add_triangle(s, {-1, -1, 1}, {1, -1, 1}, {0, 1, 1});
  s.positions.push_back(s.positions[0]);
  for (Vec3& p : s.positions[1]) p.z = 3;  // moves from depth 1 to depth 3
  const EmbreeScene es(s, 0.5, Vec3{});
  const Hit h = es.first_hit(Vec3{}, {0, 0, 1}, 0.1);
  EXPECT_EQ(h.tri, 0u);
  EXPECT_NEAR(h.lambda, 2.0, 1e-6);
}

// The see-through rule in the Embree from-point baseline: every pixel's first opaque hit and the
// see-through hits in front of it (brute_force_hits, double), nothing else.
TEST(PointVisibility, SeeThroughTrianglesAreSeenAndHideNothingAsInTheDoubleReference) {
  Scene scene = random_soup(300, 8);
  scene.objects = {{"opaque"}, {"glass", true}};
  Rng pick(3);
  for (uint32_t& o : scene.triangle_object) o = pick.uniform() < 0.4 ? 1 : 0;
  const int n = 32;
  const double z_near = 0.05;
  size_t required = 0, missed = 0, extra = 0, see_through_seen = 0;
  for (uint64_t view = 0; view < 3; ++view) {
    Rng rng(Rng::derive(77, view));
    const Vec3 eye{rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    const Mat3 R = random_orientation(Rng::derive(6, view));
    const EmbreeScene es(scene, 0.0, eye);
    ASSERT_TRUE(es.has_see_through());
    const std::vector<uint32_t> set = point_visible_set(es, eye, R, n, z_near);
    std::vector<uint32_t> reference, unstable;
    for (int f = 0; f < kCubeFaces; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const Vec3 d = pixel_direction(face_axes(f, R), x, y, n);
          const OracleRay ray = brute_force_hits(scene, 0.0, eye, d, z_near);
          if (ray.opaque.tri != kNoHit)
            (ray.opaque.ambiguous ? unstable : reference).push_back(ray.opaque.tri);
          reference.insert(reference.end(), ray.see_through.begin(), ray.see_through.end());
          unstable.insert(unstable.end(), ray.see_through_ambiguous.begin(),
                          ray.see_through_ambiguous.end());
          if (ray.opaque.ambiguous) {  // what lies behind an unstable opaque hit is unstable too
            const OracleSample all = brute_force_first_hit(scene, 0.0, eye, d, z_near);
            if (all.tri != kNoHit) unstable.push_back(all.tri);
          }
        }
    for (auto* v : {&reference, &unstable}) {
      std::sort(v->begin(), v->end());
      v->erase(std::unique(v->begin(), v->end()), v->end());
    }
    auto in = [](const std::vector<uint32_t>& v, uint32_t id) {
      return std::binary_search(v.begin(), v.end(), id);
    };
    for (uint32_t id : reference) {
      ++required;
      if (!in(set, id) && !in(unstable, id)) ++missed;
    }
    for (uint32_t id : set) {
      if (!in(reference, id) && !in(unstable, id)) ++extra;
      see_through_seen += scene.triangle_see_through(id) ? 1 : 0;
    }
  }
  EXPECT_EQ(missed, 0u) << "of " << required;
  EXPECT_EQ(extra, 0u);
  EXPECT_GT(see_through_seen, 20u);
}
