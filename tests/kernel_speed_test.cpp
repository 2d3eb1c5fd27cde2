// The kernel's speed techniques must not change any result: footprint bounds without the hull, the
// per-pixel depth culling, and the vectorised coverage are checked against the plain paths.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "tests/kernel_compare.h"
#include "tests/scene_builders.h"
#include "vislib/base/random.h"
#include "vislib/base/tolerances.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_test::identical_lists;
using vislib_test::random_soup;
using vislib_test::same_witnesses;

namespace {

// A small city street (many layers of facades, axis-aligned edges that pixel centres hit
// exactly, so the tie rule runs) plus a random soup in front of it.
Scene street_scene() {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  o.panel_size = 4;
  o.seed = 3;
  Scene s = generate_city(o);
  return s;
}

// A slanted wall (z = 2 + x / 4) with 400 small tiles 1 unit behind it and 100 decals 0.01 in
// front of it, seen from a segment that backs away from all of them. A tile is covered at a
// pixel over a short stretch of t, nearer there than the wall's farthest depth at that pixel (so
// neither the pixel's depth bound nor the plane test culls it) but behind the wall over the
// whole stretch. The wall, inserted first (its nearest depth is the smallest), is the one piece
// of every pixel that sees it, so the tiles' intervals take the one-piece test, and so do the
// decals', which must not be skipped (a test that also skipped intervals up to 1% nearer than
// the wall would skip some of them).
Scene wall_tiles_and_decals_scene() {
  auto on = [](double x, double y, double off) { return Vec3{x, y, 2 + x / 4 + off}; };
  std::vector<std::array<Vec3, 3>> tris;
  tris.push_back({on(-100, -100, 0), on(100, -100, 0), on(0, 100, 0)});
  Rng rng(5);
  for (int i = 0; i < 500; ++i) {
    const double x = rng.uniform(-3, 3), y = rng.uniform(-3, 3), off = i < 400 ? 1 : -0.01;
    tris.push_back({on(x, y, off), on(x + 0.1, y, off), on(x, y + 0.1, off)});
  }
  return vislib_test::soup(tris);
}

}  // namespace

TEST(KernelSpeed, FootprintBoundsWithoutTheHullEqualTheHullsBounds) {
  Rng rng(17);
  const int n = 64;
  int nonempty = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    Vec3 rel[6];
    for (Vec3& q : rel) q = {rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    if (trial % 3 == 0)  // small, far triangles (the common case)
      for (int i = 1; i < 6; ++i) rel[i] = rel[0] + (rel[i] - rel[0]) * 0.01;
    for (int face = 0; face < 6; ++face) {
      FaceAxes ax = face_axes(face, Mat3{});
      int a[4] = {1, 0, 1, 0}, b[4] = {1, 0, 1, 0};
      double z;
      bool ra =
          footprint_pixel_bounds(compute_footprint(rel, 6, ax, 0.05), n, a[0], a[1], a[2], a[3]);
      bool rb = footprint_bounds(rel, 6, ax, 0.05, n, b[0], b[1], b[2], b[3], z);
      ASSERT_EQ(ra, rb) << trial << " " << face;
      if (!ra) continue;
      ++nonempty;
      for (int k = 0; k < 4; ++k) ASSERT_EQ(a[k], b[k]) << trial << " " << face;
      double zmin = INFINITY;
      for (const Vec3& q : rel) zmin = std::min(zmin, dot(ax.F, q));
      EXPECT_EQ(z, zmin);
    }
  }
  EXPECT_GT(nonempty, 1000);
}

// reachable_faces decides all six faces' quick frustum reject from one set of dot products. It
// must agree face by face with the reject computed in each face's own frame (projected_points'
// test, restated here), and the footprint must be empty on every face it excludes: under random
// rotations, and with points on the frustum planes (x = +-y = z lies on several of them).
TEST(KernelSpeed, ReachableFacesAgreeWithThePerFaceRejectAndExcludeOnlyEmptyFootprints) {
  Rng rng(29);
  int excluded = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    const Mat3 R = trial % 4 == 0 ? Mat3{} : random_orientation(uint64_t(trial));
    Vec3 rel[6];
    for (Vec3& q : rel) q = {rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)};
    if (trial % 3 == 0)  // small, far triangles: most reach one face
      for (int i = 1; i < 6; ++i) rel[i] = rel[0] + (rel[i] - rel[0]) * 0.01;
    if (trial % 5 == 0)  // on frustum planes of the world-aligned cube
      for (Vec3& q : rel) q = Vec3{1, rng.uniform() < 0.5 ? 1.0 : -1.0, 1} * rng.uniform(-2, 2);
    const double near = trial % 7 == 0 ? 0.5 : 0.05;
    const unsigned mask = reachable_faces(rel, 6, R, near);
    for (int face = 0; face < 6; ++face) {
      const FaceAxes ax = face_axes(face, R);
      const double g = 1.0 + kFrustumRejectWidening;
      bool behind = true, right = true, left = true, up = true, down = true;
      for (const Vec3& r : rel) {
        const Vec3 q{dot(ax.S, r), dot(ax.T, r), dot(ax.F, r)};
        const double z = std::fabs(q.z) * g;
        behind = behind && q.z < near;
        right = right && q.x > z;
        left = left && q.x < -z;
        up = up && q.y > z;
        down = down && q.y < -z;
      }
      const bool rejected = behind || right || left || up || down;
      ASSERT_EQ(!(mask >> face & 1), rejected) << trial << " " << face;
      if (!rejected) continue;
      ++excluded;
      int b[4];
      double z;
      ASSERT_FALSE(footprint_bounds(rel, 6, ax, near, 64, b[0], b[1], b[2], b[3], z));
      ASSERT_TRUE(compute_footprint(rel, 6, ax, near).empty());
    }
  }
  EXPECT_GT(excluded, 5000);  // 8,746 with these seeds
}

TEST(KernelSpeed, VectorisedCoverageGivesBitIdenticalPiecesAndWitnesses) {
  for (int scene_kind = 0; scene_kind < 2; ++scene_kind) {
    Scene s = scene_kind == 0 ? random_soup(400, 5) : street_scene();
    for (int orient = 0; orient < 2; ++orient) {
      SegmentOptions o;
      o.resolution = 48;
      o.want_pieces = true;
      o.want_witnesses = true;
      if (orient) o.orientation = random_orientation(11);
      Vec3 v0 = scene_kind == 0 ? Vec3{-2, 0, 0} : Vec3{0, 1.7, -8},
           v1 = scene_kind == 0 ? Vec3{2, 0.5, 0} : Vec3{0, 1.7, 8};
      auto vec = segment_visibility(s, v0, v1, o);
      o.simd = false;
      auto sca = segment_visibility(s, v0, v1, o);
      EXPECT_EQ(vec.visible, sca.visible);
      EXPECT_TRUE(identical_lists(vec.pieces, sca.pieces)) << scene_kind << " " << orient;
      EXPECT_TRUE(same_witnesses(vec.witnesses, sca.witnesses));
      EXPECT_EQ(vec.stats.pair_tests, sca.stats.pair_tests);
      EXPECT_GT(vec.stats.final_pieces, 0u);
    }
  }
}

TEST(KernelSpeed, DepthCullingSkipsHiddenIntervalsAndChangesNoPiece) {
  Scene s = street_scene();
  SegmentOptions o;
  o.resolution = 48;
  o.want_pieces = true;
  o.want_witnesses = true;
  auto with = segment_visibility(s, {0, 1.7, -8}, {0, 1.7, 8}, o);
  o.depth_culling = false;
  auto without = segment_visibility(s, {0, 1.7, -8}, {0, 1.7, 8}, o);
  EXPECT_EQ(with.visible, without.visible);
  EXPECT_TRUE(identical_lists(with.pieces, without.pieces));
  EXPECT_TRUE(same_witnesses(with.witnesses, without.witnesses));
  EXPECT_EQ(without.stats.hidden_pairs, 0u);
  EXPECT_LT(with.stats.pair_tests, without.stats.pair_tests);

  // Intervals behind a covered pixel's one piece (the wall) are skipped, and nothing changes.
  Scene w = wall_tiles_and_decals_scene();
  o.depth_culling = true;
  auto hid = segment_visibility(w, {0, 0, 0}, {0, 0, -6}, o);
  o.depth_culling = false;
  auto all = segment_visibility(w, {0, 0, 0}, {0, 0, -6}, o);
  EXPECT_EQ(hid.visible, all.visible);
  EXPECT_TRUE(identical_lists(hid.pieces, all.pieces));
  EXPECT_TRUE(same_witnesses(hid.witnesses, all.witnesses));
  ASSERT_GT(hid.visible.size(), 20u);  // the wall and decals, never a tile
  EXPECT_EQ(hid.visible[0], 0u);
  EXPECT_GT(hid.visible[1], 400u);
  EXPECT_GT(hid.stats.hidden_pairs, 100u);
  EXPECT_EQ(all.stats.hidden_pairs, 0u);
}

// Without witnesses the tie closure skips the records that can only mark an id already marked
// (for_each_visible's `settled`): the visible set is still the witness run's, on a soup where every
// triangle has a coplanar copy (every covered pixel has ties) and some copies are chained three
// deep, on one thread and on all.
TEST(KernelSpeed, MarksWithoutWitnessesGiveTheVisibleSetOfTheWitnessRun) {
  Rng rng(21);
  std::vector<std::array<Vec3, 3>> tris;
  for (int i = 0; i < 300; ++i) {
    const Vec3 c{rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-10, 10)};
    std::array<Vec3, 3> t;
    for (auto& p : t) p = c + Vec3{rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)};
    for (int copies = i % 3 == 0 ? 3 : 2; copies > 0; --copies) tris.push_back(t);
  }
  const Scene s = vislib_test::soup(tris);
  for (int threads : {1, tbb::task_arena::automatic}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      SegmentOptions o;
      o.resolution = 40;
      o.want_witnesses = true;
      const auto with = segment_visibility(s, {-2, 0, 0}, {2, 0.5, 0}, o);
      o.want_witnesses = false;
      const auto without = segment_visibility(s, {-2, 0, 0}, {2, 0.5, 0}, o);
      EXPECT_EQ(with.visible, without.visible) << threads;
      EXPECT_GT(with.visible.size(), 200u);
    });
  }
}

// Long segments: one run along a segment split at s_1 < s_2 < ... gives, for
// each part, the set of a run over that part alone. The end points are chosen so that every
// junction v0 + s (v1 - v0) is exactly representable (dyadic s, integer coordinates).
TEST(SplitSegment, EachPartGivesTheSetOfARunOverThatPartAlone) {
  const Scene scene = street_scene();
  for (Vec3 dir : {Vec3{1, 0, 0}, Vec3{0, 0, 1}}) {
    const Vec3 v0 = Vec3{-8, 1.625, -8} + dir * 0.0, v1 = v0 + dir * 16.0;
    SegmentOptions o;
    o.resolution = 24;
    o.splits = {0.125, 0.25, 0.5, 0.75};
    const SegmentResult whole = segment_visibility(scene, v0, v1, o);
    ASSERT_EQ(whole.visible_parts.size(), 5u);
    std::vector<double> bounds = {0, 0.125, 0.25, 0.5, 0.75, 1};
    std::vector<uint32_t> uni;
    SegmentOptions alone = o;
    alone.splits.clear();
    for (size_t i = 0; i + 1 < bounds.size(); ++i) {
      const Vec3 a = v0 + (v1 - v0) * bounds[i], b = v0 + (v1 - v0) * bounds[i + 1];
      const SegmentResult part = segment_visibility(scene, a, b, alone);
      EXPECT_FALSE(part.visible.empty());
      EXPECT_EQ(whole.visible_parts[i], part.visible) << "part " << i;
      uni.insert(uni.end(), part.visible.begin(), part.visible.end());
    }
    std::sort(uni.begin(), uni.end());
    uni.erase(std::unique(uni.begin(), uni.end()), uni.end());
    // The union of the parts is the unsplit run's set.
    EXPECT_EQ(whole.visible, uni);
    EXPECT_EQ(segment_visibility(scene, v0, v1, alone).visible, uni);
  }
}

TEST(SplitSegment, BadSplitPointsAreRefused) {
  const Scene scene = street_scene();
  SegmentOptions o;
  o.resolution = 4;
  for (std::vector<double> bad : {std::vector<double>{0.0},
                                  {1.0},
                                  {0.5, 0.5},
                                  {0.6, 0.4},
                                  {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8}})
    EXPECT_THROW(segment_visibility(scene, {0, 1, 0}, {1, 1, 0}, (o.splits = bad, o)),
                 std::invalid_argument);
}
