// The BVH walk of the tile driver: the tree is well formed, a node's
// rectangle and depth bound those of every triangle inside it, and a run that walks the tree gives
// bit-identical lists, sets and witnesses to a run that bins every primitive (triangles, or fans:
// triangle_groups_test.cpp compares the two).
#include "vislib/kernel/triangle_bvh.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "tests/kernel_compare.h"
#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/base/random.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"

using namespace vislib;
using vislib_test::identical_lists;
using vislib_test::random_soup;
using vislib_test::same_witnesses;

namespace {

// Runs with and without the tree, for its triangles and for its fans (SegmentOptions::fans); every
// result must be the same.
void expect_walk_equals_binning(const Scene& s, Vec3 v0, Vec3 v1, SegmentOptions o,
                                const std::string& what) {
  for (const bool fans : {false, true}) {
    const TriangleBvh tree =
        build_triangle_bvh(s, fans ? BvhPrimitives::Groups : BvhPrimitives::Triangles);
    const std::string which = what + (fans ? ", fans" : ", triangles");
    o.want_pieces = true;
    o.want_witnesses = true;
    o.fans = fans;
    o.bvh = nullptr;
    const SegmentResult binned = segment_visibility(s, v0, v1, o);
    o.bvh = &tree;
    const SegmentResult walked = segment_visibility(s, v0, v1, o);
    EXPECT_EQ(walked.visible, binned.visible) << which;
    EXPECT_TRUE(identical_lists(walked.pieces, binned.pieces)) << which;
    EXPECT_TRUE(same_witnesses(walked.witnesses, binned.witnesses)) << which;
    EXPECT_EQ(walked.stats.final_pieces, binned.stats.final_pieces) << which;
  }
}

}  // namespace

TEST(TriangleBvh, EveryTriangleSitsInExactlyOneLeafInsideEveryNodeOnItsPath) {
  // Large enough that the top ranges build their halves as parallel tasks.
  const Scene s = random_soup(40000, 9);
  const TriangleBvh t = build_triangle_bvh(s);
  ASSERT_FALSE(t.nodes.empty());
  std::vector<int> seen(s.triangle_count(), 0);
  size_t visited = 0;
  // Walk from the root keeping the path's boxes; each triangle's corners lie inside them all.
  struct Item {
    uint32_t node;
    std::vector<uint32_t> path;
  };
  std::vector<Item> stack{{0, {}}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    it.path.push_back(it.node);
    ++visited;
    const TriangleBvh::Node& n = t.nodes[it.node];
    if (n.count == 0) {
      ASSERT_LT(n.first + 1, t.nodes.size());
      stack.push_back({n.first, it.path});
      stack.push_back({n.first + 1, it.path});
      continue;
    }
    EXPECT_LE(n.count, kBvhLeafSize);
    for (uint32_t i = n.first; i < n.first + n.count; ++i) {
      const uint32_t tri = t.order[i];
      ++seen[tri];
      for (uint32_t p : it.path)
        for (const Vec3& c : s.corners(tri))
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(double(t.nodes[p].lo[a]), c[a]);
            EXPECT_GE(double(t.nodes[p].hi[a]), c[a]);
          }
    }
  }
  for (int c : seen) EXPECT_EQ(c, 1);
  EXPECT_EQ(visited, t.nodes.size());  // no slot left out of the tree
  // Deterministic.
  const TriangleBvh u = build_triangle_bvh(s);
  EXPECT_EQ(u.order, t.order);
  ASSERT_EQ(u.nodes.size(), t.nodes.size());
  EXPECT_EQ(std::memcmp(u.nodes.data(), t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0])), 0);
}

TEST(TriangleBvh, TheTreeIsTheSameWhateverTheThreadCount) {
  // Large enough that the top ranges build their halves as parallel tasks.
  const Scene s = random_soup(50000, 21);
  TriangleBvh one, many;
  tbb::task_arena(1).execute([&] { one = build_triangle_bvh(s); });
  tbb::task_arena(4).execute([&] { many = build_triangle_bvh(s); });
  ASSERT_EQ(one.nodes.size(), many.nodes.size());
  EXPECT_EQ(0, std::memcmp(one.nodes.data(), many.nodes.data(),
                           one.nodes.size() * sizeof(TriangleBvh::Node)));
  EXPECT_EQ(one.order, many.order);
}

// box_footprint_bounds must contain the footprint rectangle of every triangle inside the box and
// lie below its nearest depth, or say "empty" only when the triangle's is empty, for boxes in
// front of, around and behind the eye, under random orientations.
TEST(TriangleBvh, BoxFootprintContainsTheFootprintOfEveryTriangleInside) {
  Rng rng(23);
  const int n = 64;
  const double near = 0.05;
  int straddling = 0, partial = 0, empty_tri = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Mat3 R = trial % 2 ? random_orientation(uint64_t(trial)) : Mat3{};
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      const double c = rng.uniform(-6, 6), h = rng.uniform(0.01, trial % 5 == 0 ? 4.0 : 1.0);
      lo[a] = float(c - h);
      hi[a] = float(c + h);
    }
    const Vec3 v0{rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)};
    const Vec3 v1 =
        trial % 3 == 0 ? v0 : Vec3{rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-4, 4)};
    for (int k = 0; k < 6; ++k) {
      const FaceAxes ax = face_axes(k, R);
      int b[4];
      double bz = 0;
      const bool box_ok =
          box_footprint_bounds(lo, hi, v0, v1, ax, near, n, b[0], b[1], b[2], b[3], bz);
      if (box_ok && b[0] == 0 && b[1] == n - 1 && b[2] == 0 && b[3] == n - 1) ++straddling;
      for (int tri = 0; tri < 4; ++tri) {
        Vec3 c[3];
        for (Vec3& p : c)
          for (int a = 0; a < 3; ++a) {
            // Corners on the box's faces and edges too (u in {0, 1} a third of the time).
            double u = rng.uniform(0, 1);
            if (rng.uniform(0, 1) < 0.33) u = u < 0.5 ? 0 : 1;
            p[a] = double(lo[a]) + u * (double(hi[a]) - double(lo[a]));
          }
        const Vec3 rel[6] = {c[0] - v0, c[1] - v0, c[2] - v0, c[0] - v1, c[1] - v1, c[2] - v1};
        int t[4];
        double tz = 0;
        const bool tri_ok = footprint_bounds(rel, 6, ax, near, n, t[0], t[1], t[2], t[3], tz);
        if (!tri_ok) {
          ++empty_tri;
          continue;
        }
        ASSERT_TRUE(box_ok) << trial << " face " << k;
        ++partial;
        EXPECT_LE(b[0], t[0]) << trial;
        EXPECT_GE(b[1], t[1]) << trial;
        EXPECT_LE(b[2], t[2]) << trial;
        EXPECT_GE(b[3], t[3]) << trial;
        EXPECT_LE(bz, tz) << trial;
      }
    }
  }
  EXPECT_GT(straddling, 100);
  EXPECT_GT(partial, 5000);
  EXPECT_GT(empty_tri, 5000);
}

TEST(TriangleBvh, WalkGivesTheListsSetsAndWitnessesOfBinningOnACityStreet) {
  const Scene s = vislib_test::panel_city();
  Rng rng(5);
  for (int k = 0; k < 6; ++k) {
    SegmentOptions o;
    const auto [v0, v1] = vislib_test::panel_city_street(rng, k, o);
    if (k == 4) o.coplanar = CoplanarRule::First;
    if (k == 5) o.depth_culling = false;
    expect_walk_equals_binning(s, v0, v1, o, "street case " + std::to_string(k));
  }
}

TEST(TriangleBvh, WalkGivesTheListsSetsAndWitnessesOfBinningInARandomSoup) {
  const Scene s = random_soup(600, 41);
  for (int k = 0; k < 3; ++k) {
    SegmentOptions o;
    o.resolution = 40;
    o.tile_size = k == 2 ? 8 : 32;
    if (k) o.orientation = random_orientation(7 + uint64_t(k));
    expect_walk_equals_binning(s, {-2, 0, 0}, {2, 0.5, 0.25}, o, "soup case " + std::to_string(k));
  }
}

TEST(TriangleBvh, WalkGivesTheResultsOfBinningOnSauerPandora) {
  VISLIB_REQUIRE_SHARED(shared);
  const Scene s = load_scene(shared + "/scenes/sauer_pandora/pandora.obj");
  SegmentOptions o;
  o.resolution = 48;
  expect_walk_equals_binning(s, {-200, 40, 0}, {-100, 40, 0}, o, "pandora");
  o.orientation = random_orientation(3);
  expect_walk_equals_binning(s, {-150, 40, 20}, {-148, 41, 20}, o, "pandora short");
}

TEST(TriangleBvh, ATreeOfAnotherSceneOrStateIsRefused) {
  const Scene a = random_soup(50, 1), b = random_soup(50, 2);
  const TriangleBvh tree = build_triangle_bvh(a);
  SegmentOptions o;
  o.resolution = 8;
  o.bvh = &tree;
  EXPECT_NO_THROW(segment_visibility(a, {0, 0, 0}, {1, 0, 0}, o));
  EXPECT_THROW(segment_visibility(b, {0, 0, 0}, {1, 0, 0}, o), std::invalid_argument);
  EXPECT_THROW(build_triangle_bvh(a, 3), std::invalid_argument);
  const TriangleBvh none = build_triangle_bvh(Scene{});
  EXPECT_TRUE(none.nodes.empty());
}
