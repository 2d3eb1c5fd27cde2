// See-through triangles (Object::see_through): seen, never hiding anything. Semantic cases of the
// from-segment kernel, its tie rule, and a seeded property test against the double-precision
// brute-force oracle under the same rule (brute_force_hits: a ray passes through see-through hits
// and records each one until the first opaque hit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "tests/scene_builders.h"
#include "tests/support/ray_oracle.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/kernel/triangle_bvh.h"

using namespace vislib;

namespace {

bool contains(const std::vector<uint32_t>& v, uint32_t id) {
  return std::binary_search(v.begin(), v.end(), id);
}

// Re-casts every witness of `r` with brute_force_hits: the witnessed triangle must be the first
// opaque hit or a see-through hit in front of it, or lie within 2 eps_z of the opaque hit (a tie),
// or be ambiguous there. Returns the failures.
int witness_failures(const Scene& s, const SegmentResult& r, Vec3 v0, Vec3 v1,
                     const SegmentOptions& o) {
  int failures = 0;
  for (const Witness& w : r.witnesses) {
    const Vec3 eye = lerp(v0, v1, w.t);
    const Vec3 d = pixel_direction(face_axes(w.face, o.orientation), w.x, w.y, o.resolution);
    const OracleRay ray = brute_force_hits(s, 0.0, eye, d, o.near);
    if (ray.opaque.tri == w.tri || contains(ray.see_through, w.tri)) continue;
    if (ray.opaque.ambiguous ||
        std::find(ray.see_through_ambiguous.begin(), ray.see_through_ambiguous.end(), w.tri) !=
            ray.see_through_ambiguous.end())
      continue;
    const double mine = triangle_depth(s, w.tri, eye, d, o.near);
    if (ray.opaque.tri != kNoHit && std::fabs(mine - ray.opaque.lambda) <= 2 * o.eps_z * mine)
      continue;
    ++failures;
  }
  return failures;
}

}  // namespace

TEST(SegmentVisibilitySeeThrough, SeeThroughQuadInFrontOfAnOpaqueTriangleLeavesBothVisible) {
  Scene s;
  vislib_test::add_quad(s, {-10, -10, 5}, {10, -10, 5}, {10, 10, 5}, {-10, 10, 5});  // glass 0-1
  s.objects[0].see_through = true;
  vislib_test::add_quad(s, {-1, -1, 8}, {1, -1, 8}, {1, 1, 8}, {-1, 1, 8});  // behind it, 2-3
  SegmentOptions o;
  o.resolution = 64;
  o.want_witnesses = true;
  const Vec3 v0{-1, 0, 0}, v1{1, 0, 0};
  auto r = segment_visibility(s, v0, v1, o);
  EXPECT_EQ(r.visible, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(witness_failures(s, r, v0, v1, o), 0);
  // The same glass opaque hides the quad.
  s.objects[0].see_through = false;
  EXPECT_EQ(segment_visibility(s, v0, v1, o).visible, (std::vector<uint32_t>{0, 1}));
}

TEST(SegmentVisibilitySeeThrough, OpaqueQuadInFrontHidesASeeThroughOne) {
  Scene s;
  vislib_test::add_quad(s, {-10, -10, 5}, {10, -10, 5}, {10, 10, 5}, {-10, 10, 5});  // wall 0-1
  vislib_test::add_quad(s, {-1, -1, 8}, {1, -1, 8}, {1, 1, 8}, {-1, 1, 8});          // water 2-3
  s.objects[1].see_through = true;
  SegmentOptions o;
  o.resolution = 64;
  auto r = segment_visibility(s, {-1, 0, 0}, {1, 0, 0}, o);
  EXPECT_EQ(r.visible, (std::vector<uint32_t>{0, 1}));
}

TEST(SegmentVisibilitySeeThrough, SeeThroughAtADepthTieWithAnOpaqueSurfaceIsVisible) {
  // The see-through quad has the lower ids and lies in the opaque wall's plane (an exact tie) or
  // just behind it, within eps_z: visible under both coplanar rules where exact, under Both when
  // within the tolerance; farther behind, hidden.
  for (double behind : {0.0, 2e-6, 1e-3}) {
    for (CoplanarRule rule : {CoplanarRule::Both, CoplanarRule::First}) {
      Scene s;
      const double z = 5 + behind;
      vislib_test::add_quad(s, {-2, -2, z}, {2, -2, z}, {2, 2, z}, {-2, 2, z});  // water 0-1
      s.objects[0].see_through = true;
      // (Half-sizes 2 and 8: the plane normals are powers of two, so an exact tie stays exact.)
      vislib_test::add_quad(s, {-8, -8, 5}, {8, -8, 5}, {8, 8, 5}, {-8, 8, 5});  // wall 2-3
      SegmentOptions o;
      o.resolution = 32;
      o.coplanar = rule;
      o.want_witnesses = true;
      const Vec3 v0{-1, 0, 0}, v1{1, 0, 0};
      auto r = segment_visibility(s, v0, v1, o);
      const bool expect = behind == 0.0 || (behind < 5 * o.eps_z && rule == CoplanarRule::Both);
      EXPECT_EQ(contains(r.visible, 0), expect) << "behind " << behind << " rule " << int(rule);
      EXPECT_TRUE(contains(r.visible, 2) && contains(r.visible, 3));  // never hidden by a tie
      EXPECT_EQ(witness_failures(s, r, v0, v1, o), 0);
    }
  }
}

TEST(SegmentVisibilitySeeThrough, SeeThroughTrianglesLeaveTheOpaqueListsAndMarksUnchanged) {
  Scene s = vislib_test::random_soup(400, 7, 10, 2);
  Rng rng(11);
  for (Object& ob : s.objects) ob.see_through = rng.uniform() < 0.3;
  // The same scene with every see-through triangle collapsed to a point: it covers nothing and
  // keeps the ids.
  Scene without = s;
  for (Object& ob : without.objects) ob.see_through = false;
  for (size_t t = 0; t < s.triangle_count(); ++t)
    if (s.triangle_see_through(uint32_t(t)))
      without.triangles[t] = {s.triangles[t][0], s.triangles[t][0], s.triangles[t][0]};
  SegmentOptions o;
  o.resolution = 48;
  o.want_pieces = true;
  const Vec3 v0{-3, 0.5, 0}, v1{2, -1, 1};
  auto a = segment_visibility(s, v0, v1, o), b = segment_visibility(without, v0, v1, o);
  std::vector<uint32_t> opaque_part;
  size_t see_through_seen = 0;
  for (uint32_t id : a.visible) {
    if (s.triangle_see_through(id))
      ++see_through_seen;
    else
      opaque_part.push_back(id);
  }
  EXPECT_EQ(opaque_part, b.visible);
  EXPECT_GT(see_through_seen, 0u);
  ASSERT_EQ(a.pieces.size(), b.pieces.size());
  for (size_t k = 0; k < a.pieces.size(); ++k) {
    ASSERT_EQ(a.pieces[k].size(), b.pieces[k].size()) << "pixel " << k;
    for (size_t i = 0; i < a.pieces[k].size(); ++i) {
      EXPECT_EQ(a.pieces[k][i].id, b.pieces[k][i].id);
      EXPECT_EQ(a.pieces[k][i].t0, b.pieces[k][i].t0);
      EXPECT_EQ(a.pieces[k][i].t1, b.pieces[k][i].t1);
    }
  }
}

TEST(SegmentVisibilitySeeThrough, SameSetWithBvhWithoutCullingAndAsUnionOfSplitParts) {
  Scene s = vislib_test::random_soup(600, 3, 10, 2);
  Rng rng(5);
  for (Object& ob : s.objects) ob.see_through = rng.uniform() < 0.25;
  SegmentOptions o;
  o.resolution = 48;
  o.want_witnesses = true;
  const Vec3 v0{0, 0, -2}, v1{1, 2, 3};
  auto plain = segment_visibility(s, v0, v1, o);
  SegmentOptions nc = o;
  nc.depth_culling = false;
  auto unculled = segment_visibility(s, v0, v1, nc);
  EXPECT_EQ(plain.visible, unculled.visible);
  TriangleBvh bvh = build_triangle_bvh(s);
  SegmentOptions ob = o;
  ob.bvh = &bvh;
  auto with_bvh = segment_visibility(s, v0, v1, ob);
  EXPECT_EQ(plain.visible, with_bvh.visible);
  ASSERT_EQ(plain.witnesses.size(), with_bvh.witnesses.size());
  for (size_t i = 0; i < plain.witnesses.size(); ++i) {
    EXPECT_EQ(plain.witnesses[i].face, with_bvh.witnesses[i].face);
    EXPECT_EQ(plain.witnesses[i].x, with_bvh.witnesses[i].x);
    EXPECT_EQ(plain.witnesses[i].y, with_bvh.witnesses[i].y);
    EXPECT_EQ(plain.witnesses[i].t, with_bvh.witnesses[i].t);
  }
  SegmentOptions os = o;
  os.want_witnesses = false;
  os.splits = {0.3, 0.7};
  auto split = segment_visibility(s, v0, v1, os);
  ASSERT_EQ(split.visible_parts.size(), 3u);
  for (const auto& part : split.visible_parts)
    for (uint32_t id : part) EXPECT_TRUE(contains(plain.visible, id)) << id;
  // Each part alone gives the part's set.
  for (int i = 0; i < 3; ++i) {
    const double a = i == 0 ? 0 : os.splits[size_t(i - 1)], b = i == 2 ? 1 : os.splits[size_t(i)];
    auto alone = segment_visibility(s, lerp(v0, v1, a), lerp(v0, v1, b), o);
    std::vector<uint32_t> diff;
    std::set_symmetric_difference(alone.visible.begin(), alone.visible.end(),
                                  split.visible_parts[size_t(i)].begin(),
                                  split.visible_parts[size_t(i)].end(), std::back_inserter(diff));
    EXPECT_LE(diff.size(), 2u) << "part " << i;  // (rounding of t at the part's ends)
  }
}

TEST(SegmentVisibilitySeeThrough, DynamicScenesAndSpheresWithSeeThroughObjectsAreRefused) {
  Scene s;
  vislib_test::add_quad(s, {-10, -10, 5}, {10, -10, 5}, {10, 10, 5}, {-10, 10, 5});
  s.objects[0].see_through = true;
  s.positions.push_back(s.positions[0]);
  s.positions[1][0].z += 1;  // moves
  SegmentOptions o;
  o.resolution = 16;
  try {
    segment_visibility(s, {-1, 0, 0}, {1, 0, 0}, o);
    FAIL() << "a moving scene with a see-through object was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("see-through"), std::string::npos) << e.what();
  }
  s.positions.pop_back();
  s.sphere_radius.push_back(1);
  s.sphere_centers.assign(1, {Vec3{0, 0, 9}});
  s.sphere_object.push_back(0);
  EXPECT_THROW(segment_visibility(s, {-1, 0, 0}, {1, 0, 0}, o), std::invalid_argument);
}

// Seeded property test: random soups with a share of see-through triangles; every unambiguous
// hit of brute_force_hits at random t through every pixel centre is in the kernel's set (nothing
// missed), and every witness re-casts to its triangle (nothing extra). About a second.
TEST(SegmentOracleSeeThrough, RandomSoupWithSeeThroughShareHasNoMissAndEveryWitnessRecasts) {
  for (uint64_t seed : {21u, 22u, 23u}) {
    Scene s = vislib_test::random_soup(900, seed, 6, 2.5);  // dense: most of it hidden
    Rng rng(Rng::derive(seed, 1));
    size_t marked = 0;
    for (Object& ob : s.objects) {
      ob.see_through = rng.uniform() < 0.35;
      marked += ob.see_through;
    }
    ASSERT_GT(marked, 0u);
    const Vec3 v0{rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    const Vec3 v1 = v0 + Vec3{rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)};
    SegmentOptions o;
    o.resolution = 24;
    o.near = 1e-3;
    o.orientation = random_orientation(Rng::derive(seed, 2));
    o.want_witnesses = true;
    auto r = segment_visibility(s, v0, v1, o);
    uint64_t checked = 0, ambiguous = 0, misses = 0, see_through_hits = 0;
    std::string first;
    for (int face = 0; face < kCubeFaces; ++face)
      for (int y = 0; y < o.resolution; ++y)
        for (int x = 0; x < o.resolution; ++x)
          for (int k = 0; k < 3; ++k) {
            const double t = rng.uniform();
            const Vec3 d = pixel_direction(face_axes(face, o.orientation), x, y, o.resolution);
            const OracleRay ray = brute_force_hits(s, 0.0, lerp(v0, v1, t), d, o.near);
            auto need = [&](uint32_t id) {
              ++checked;
              if (contains(r.visible, id)) return;
              ++misses;
              if (first.empty())
                first = "triangle " + std::to_string(id) + " at face " + std::to_string(face) +
                        " pixel " + std::to_string(x) + "," + std::to_string(y) + " t " +
                        std::to_string(t);
            };
            if (ray.opaque.ambiguous)
              ++ambiguous;
            else if (ray.opaque.tri != kNoHit)
              need(ray.opaque.tri);
            for (uint32_t id : ray.see_through) need(id);
            see_through_hits += ray.see_through.size();
            ambiguous += ray.see_through_ambiguous.size();
          }
    EXPECT_EQ(misses, 0u) << "seed " << seed << ": " << first;
    EXPECT_GT(see_through_hits, 100u) << "seed " << seed;
    EXPECT_LT(double(ambiguous), 0.01 * double(checked)) << "seed " << seed;
    EXPECT_EQ(witness_failures(s, r, v0, v1, o), 0) << "seed " << seed;
    std::printf(
        "[see-through oracle] seed %llu: %zu visible, %llu hits checked (%llu see-through), "
        "%llu ambiguous, %zu witnesses re-cast\n",
        (unsigned long long)seed, r.visible.size(), (unsigned long long)checked,
        (unsigned long long)see_through_hits, (unsigned long long)ambiguous, r.witnesses.size());
  }
}
