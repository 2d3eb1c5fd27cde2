// Runs of collinear edges (vislib/kernel/edge_lines.h) and the leak they close: a T-junction
// across a corner, seen along its line.
#include "vislib/kernel/edge_lines.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "tests/scene_builders.h"
#include "vislib/base/random.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_test::soup;

TEST(EdgeLines, CollinearEdgesThroughSharedEndpointsShareTheRunsExtremePoints) {
  // Three edges on the line y = 448, z = -1792 (a map's T-junctions): [32, 272], [224, 448] and
  // [224, 272], joined through 272 and 224; a fourth triangle is merely parallel (y = 450).
  Scene s = soup({{Vec3{32, 448, -1792}, {272, 448, -1792}, {272, 448, -1784}},
                  {Vec3{448, 448, -1792}, {224, 448, -1792}, {224, 448, -1824}},
                  {Vec3{480, 640, -1792}, {272, 448, -1792}, {224, 448, -1792}},
                  {Vec3{0, 450, -1792}, {500, 450, -1792}, {0, 450, -1700}}});
  const EdgeLines el = build_edge_lines(s);
  ASSERT_TRUE(el.matches(s, 0));
  EXPECT_EQ(el.edge_count(), 3u);
  EXPECT_EQ(el.lines.size(), 1u);
  Vec3 P, Q;
  ASSERT_TRUE(el.line_of(0, 0, P, Q));
  EXPECT_EQ(P, (Vec3{32, 448, -1792}));
  EXPECT_EQ(Q, (Vec3{448, 448, -1792}));
  ASSERT_TRUE(el.line_of(1, 0, P, Q));
  EXPECT_EQ(P, (Vec3{32, 448, -1792}));
  ASSERT_TRUE(el.line_of(2, 1, P, Q));
  EXPECT_EQ(Q, (Vec3{448, 448, -1792}));
  EXPECT_FALSE(el.line_of(0, 1, P, Q));
  EXPECT_FALSE(el.line_of(3, 0, P, Q));
}

TEST(EdgeLines, TheRunsAreTheSameWhateverTheThreadCount) {
  CityOptions o;
  o.blocks_x = o.blocks_z = 3;
  o.panel_size = 2;  // small panels: many collinear edges through shared corners
  o.seed = 5;
  const Scene s = generate_city(o);
  EdgeLines one, many;
  tbb::task_arena(1).execute([&] { one = build_edge_lines(s, 0); });
  tbb::task_arena(4).execute([&] { many = build_edge_lines(s, 0); });
  ASSERT_FALSE(one.lines.empty());
  EXPECT_EQ(one.edge_line, many.edge_line);
  EXPECT_EQ(one.lines, many.lines);
}

// The points are joined range by range in bounded memory (kEdgeLinesIncidentBudget): ranges of
// one point each (a budget below any degree still takes one) and of a few hundred points give
// the runs of one range holding every point.
TEST(EdgeLines, TheRunsAreTheSameWhateverTheIncidentListsBudget) {
  CityOptions o;
  o.blocks_x = o.blocks_z = 1;
  o.panel_size = 2;
  o.seed = 6;
  const Scene s = generate_city(o);
  const EdgeLines whole = build_edge_lines(s, 0, s.triangle_count() * 6);
  ASSERT_FALSE(whole.lines.empty());
  for (size_t budget : {size_t(1), size_t(2000)}) {
    const EdgeLines ranged = build_edge_lines(s, 0, budget);
    EXPECT_EQ(ranged.edge_line, whole.edge_line) << "budget " << budget;
    EXPECT_EQ(ranged.lines, whole.lines) << "budget " << budget;
  }
}

TEST(EdgeLines, SharedEdgesAloneAndCollinearEdgesThatNeverTouchMakeNoRun) {
  // Two triangles sharing one whole edge, and a third on the same line but apart: each edge keeps
  // its own points (bit-identical on the shared edge already).
  Scene s = soup({{Vec3{0, 0, 0}, {4, 0, 0}, {2, 3, 0}},
                  {Vec3{4, 0, 0}, {0, 0, 0}, {2, -3, 0}},
                  {Vec3{6, 0, 0}, {9, 0, 0}, {7, 2, 0}}});
  const EdgeLines el = build_edge_lines(s);
  EXPECT_EQ(el.edge_count(), 0u);
  EXPECT_TRUE(el.edge_line.empty());
}

TEST(EdgeLines, KernelRefusesEdgeLinesOfAnotherScene) {
  Scene a = soup({{Vec3{0, 0, 5}, {1, 0, 5}, {0, 1, 5}}});
  Scene b = a;
  const EdgeLines el = build_edge_lines(b);
  SegmentOptions o;
  o.resolution = 4;
  o.edge_lines = &el;
  EXPECT_THROW(segment_visibility(a, {0, 0, 0}, {0.1, 0, 0}, o), std::invalid_argument);
}

// A closed corner seen from inside: wall A (z = Z0, x <= X0) and wall B (x = X0, z <= Z0) meet on
// the line x = X0, z = Z0, where A has one edge and B two (a vertex of B on A's edge: a T-junction
// across the corner). A segment parallel to that line, placed so that a pixel ray passes through
// the line (to within rounding) over the whole segment. Nothing behind the walls may be seen.
TEST(EdgeLines, TJunctionAcrossACornerSeenAlongItsLineLeaksNothing) {
  Rng rng(7);
  const int N = 8;
  size_t leaks_with = 0, leaks_without = 0, configs = 0;
  for (int k = 0; k < 64; ++k) {
    const double X0 = 576 + rng.uniform() * 64, Z0 = 1840 - rng.uniform() * 64;
    const double W = 1000;  // walls far wider than any ray's reach to the background
    const double yb = -W + 2 * W * (0.3 + 0.4 * rng.uniform());  // B's vertex on A's edge
    Scene s = soup({
        // A: plane z = Z0, x in [X0 - W, X0]; its edge on the corner line is one edge.
        {Vec3{X0, -W, Z0}, {X0, W, Z0}, {X0 - W, W, Z0}},
        {Vec3{X0, -W, Z0}, {X0 - W, W, Z0}, {X0 - W, -W, Z0}},
        // B: plane x = X0, z in [Z0 - W, Z0]; its edges on the line meet at y = yb.
        {Vec3{X0, yb, Z0}, {X0, -W, Z0}, {X0, -W, Z0 - W}},
        {Vec3{X0, yb, Z0}, {X0, -W, Z0 - W}, {X0, W, Z0 - W}},
        {Vec3{X0, yb, Z0}, {X0, W, Z0 - W}, {X0, W, Z0}},
    });
    const uint32_t bg = uint32_t(s.triangle_count());
    vislib_test::add_quad(s, {X0 - 20, -20, Z0 + 50}, {X0 + 20, -20, Z0 + 50},
                          {X0 + 20, 20, Z0 + 50}, {X0 - 20, 20, Z0 + 50});
    // +Z face, identity orientation: pixel (x, y) looks along (sc, -tc, 1). The eye sits at
    // depth h in front of A and at sc * h from B, so that pixel's ray meets the corner line.
    for (int px = N / 2; px < N; ++px) {
      const double sc = (2.0 * px + 1) / N - 1, h = 0.25 + rng.uniform();
      const double ex = X0 - sc * h, ez = Z0 - h;
      const double y0 = -0.5 - rng.uniform(), y1 = y0 + 0.7;
      SegmentOptions o;
      o.resolution = N;
      o.want_witnesses = false;
      const SegmentResult with = segment_visibility(s, {ex, y0, ez}, {ex, y1, ez}, o);
      EdgeLines none;  // the kernel's coefficients from each edge's own points
      none.scene = &s;
      none.triangle_count = s.triangle_count();
      o.edge_lines = &none;
      const SegmentResult without = segment_visibility(s, {ex, y0, ez}, {ex, y1, ez}, o);
      auto sees_bg = [&](const SegmentResult& r) {
        return std::find(r.visible.begin(), r.visible.end(), bg) != r.visible.end() ||
               std::find(r.visible.begin(), r.visible.end(), bg + 1) != r.visible.end();
      };
      leaks_with += sees_bg(with);
      leaks_without += sees_bg(without);
      ++configs;
    }
  }
  EXPECT_EQ(leaks_with, 0u) << "of " << configs << " segments";
  // The configuration does reach the crack: without the runs' lines, rounding lets some through.
  EXPECT_GT(leaks_without, 0u) << "of " << configs << " segments";
}
