// Restriction of runs to a bound of what they can see (kernel/triangle_bvh.h subset trees,
// bake/bsp_bound.h): a run composites only its bound's triangles, the portal flow's bound holds
// every triangle sampled eyes see on the shared maps, and leaf sets are the same with and without
// the restriction.
#include "vislib/bake/bsp_bound.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/eval/pvs_check.h"
#include "vislib/kernel/edge_lines.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/quake_bsp_volumes.h"

using namespace vislib;
using namespace vislib_test;

namespace {

Scene load_see_through(const std::string& path) {
  LoadOptions o;
  o.bsp_liquids = BspLiquids::see_through;
  return load_scene(path, o);
}

// A wall (triangles 0, 1) at z = 5 in front of a far wall (2, 3) at z = 10, seen from a segment
// at z = 0 looking along +z, and a small triangle (4) beside the eye, in plain view.
Scene wall_before_wall() {
  Scene s;
  add_quad(s, {-50, -50, 5}, {50, -50, 5}, {50, 50, 5}, {-50, 50, 5});
  add_quad(s, {-60, -60, 10}, {60, -60, 10}, {60, 60, 10}, {-60, 60, 10});
  s.positions[0].push_back({3, -1, 1});
  s.positions[0].push_back({4, -1, 1});
  s.positions[0].push_back({3, 1, 1});
  const uint32_t b = uint32_t(s.positions[0].size()) - 3;
  s.objects.push_back({"side"});
  s.triangles.push_back({b, b + 1, b + 2});
  s.triangle_object.push_back(2);
  return s;
}

}  // namespace

// A tree over a subset that holds every triangle the segment sees gives the same visible set; one
// that leaves out the near wall shows the far wall behind it: the run composites the subset alone,
// occluders included, and reports the scene's ids.
TEST(RunRestriction, SubsetTreeRunsSeeTheSameSetWhenTheSubsetHoldsItAndTheSubsetAloneOtherwise) {
  const Scene s = wall_before_wall();
  const TriangleBvh all = build_triangle_bvh(s);
  const EdgeLines lines = build_edge_lines(s);
  RegionOptions o;
  o.segment.resolution = 32;
  o.segment.bvh = &all;
  o.segment.edge_lines = &lines;
  const std::vector<Segment> segs = {Segment{{-1, 0, 0}, {1, 0, 0}}};
  const std::vector<uint32_t> want = segments_visibility(s, segs, o).visible;
  ASSERT_EQ(want, (std::vector<uint32_t>{0, 1, 4}));

  const TriangleBvh holds = build_triangle_bvh(s, 0, {0, 1, 4});
  RegionOptions bounded = o;
  bounded.segment_bvhs = {&holds};
  EXPECT_EQ(segments_visibility(s, segs, bounded).visible, want);

  const TriangleBvh without_near_wall = build_triangle_bvh(s, 0, {2, 3, 4});
  bounded.segment_bvhs = {&without_near_wall};
  EXPECT_EQ(segments_visibility(s, segs, bounded).visible, (std::vector<uint32_t>{2, 3, 4}));

  const TriangleBvh none = build_triangle_bvh(s, 0, {});
  bounded.segment_bvhs = {&none};
  EXPECT_TRUE(segments_visibility(s, segs, bounded).visible.empty());
  EXPECT_THROW(build_triangle_bvh(s, 0, {2, 1}), std::invalid_argument);
  EXPECT_THROW(build_triangle_bvh(s, 0, {5}), std::invalid_argument);
}

// The portal flow's bound of each sampled leaf (its own triangles and the bounds of its portals)
// has no sampled miss: every triangle that random eyes in the leaf's view region see (Embree
// cubemaps, each hit re-cast in double) lies in it. Its size is printed beside the map's vis.
// Time budget: 40 s on the 2-core host (bounds of the three maps, 4 eyes in 40 leaves each).
TEST(RunRestrictionLibreQuake, PortalFlowBoundHoldsEverySampledHitOnTheThreeMaps) {
  bool any = false;
  for (const char* name : {"lqdm1.bsp", "e1m2.bsp", "e2m3.bsp"}) {
    auto path = librequake(name);
    if (!path) continue;
    any = true;
    const QuakeBsp bsp = read_quake_bsp(*path);
    const Scene scene = load_see_through(*path);
    const std::vector<uint32_t> all = bsp_cell_leaves(bsp);
    const std::vector<BspPortal> portals = bsp_leaf_portals(bsp_leaf_pieces(bsp), all);
    const auto bound_leaves = bsp_portal_bound_leaves(bsp, portals, BspBound::Portals);
    const auto leaf_triangles = bsp_leaf_triangles(bsp, scene);
    std::vector<uint32_t> leaves;
    for (size_t i = 0; i < all.size(); i += std::max<size_t>(1, all.size() / 40))
      leaves.push_back(all[i]);
    std::vector<std::vector<uint32_t>> sets;
    double bound_size = 0, vis_size = 0, bound_tris = 0;
    for (uint32_t leaf : leaves) {
      std::vector<uint32_t> cell_leaves{leaf};
      for (size_t p = 0; p < portals.size(); ++p)
        if (portals[p].leaves[0] == leaf || portals[p].leaves[1] == leaf)
          cell_leaves.insert(cell_leaves.end(), bound_leaves[p].begin(), bound_leaves[p].end());
      std::sort(cell_leaves.begin(), cell_leaves.end());
      cell_leaves.erase(std::unique(cell_leaves.begin(), cell_leaves.end()), cell_leaves.end());
      sets.push_back(bound_triangles(leaf_triangles, cell_leaves));
      bound_tris += double(sets.back().size());
      bound_size += double(cell_leaves.size());
      vis_size += double(bsp_leaf_sees(bsp, leaf).size());
    }
    PvsCheckOptions o;
    o.samples = 4;
    const PvsCheckResult r =
        pvs_check(scene, bsp_leaf_eye_regions(bsp, leaves, kDefaultNear), sets, o);
    const PvsCheckTotals t = pvs_check_totals(r);
    std::printf(
        "%s: %zu leaves sampled, %llu rays; bound %.1f leaves and %.0f triangles (of %zu) "
        "a leaf, the map's vis %.1f leaves\n",
        name, leaves.size(), (unsigned long long)t.rays, bound_size / leaves.size(),
        bound_tris / leaves.size(), scene.triangle_count(), vis_size / leaves.size());
    EXPECT_GT(t.rays, 0u) << name;
    for (const PvsCheckCell& c : r.cells)
      EXPECT_EQ(c.miss_rays, 0u) << name << " leaf " << leaves[c.cell];
  }
  if (!any) GTEST_SKIP() << "../shared/scenes/librequake is absent";
}

// lqdm1's leaves have the same sets with the runs restricted to the portal flow's bound, to the
// map's vis and not at all (the sets the bake writes: runs and own triangles). Time budget: 20 s
// on the 2-core host (8 leaves at N = 32, three times; 3 leaves under AddressSanitizer).
TEST(RunRestrictionLibreQuake, Lqdm1LeafSetsAreTheSameWithAndWithoutTheRestriction) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const QuakeBsp bsp = read_quake_bsp(*path);
  const Scene scene = load_see_through(*path);
  const TriangleBvh tree = build_triangle_bvh(scene);
  const EdgeLines lines = build_edge_lines(scene);
  BspCellOptions co;
  co.sweep = BspSweep::Portals;
  co.adaptive = kBspPortalChords;
  co.scene.bsp_liquids = BspLiquids::see_through;
#if defined(__SANITIZE_ADDRESS__)
  co.leaves = {5, 120, 250};  // AddressSanitizer multiplies the runs' cost about fivefold
#else
  co.leaves = {5, 40, 77, 120, 160, 200, 250, 300};
#endif
  RegionOptions ro;
  ro.segment.resolution = 32;
  ro.segment.bvh = &tree;
  ro.segment.edge_lines = &lines;
  std::vector<std::vector<uint32_t>> want;
  for (BspBound bound : {BspBound::None, BspBound::Portals, BspBound::MapVis}) {
    co.bound = bound;
    const ViewCells cells = bsp_leaf_cells(bsp, co, &scene);
    EXPECT_EQ(cells.bound_leaves.empty(), bound == BspBound::None);
    size_t smaller = 0;  // portals whose bound leaves some triangle out
    for (const std::vector<uint32_t>& leaves : cells.bound_leaves)
      smaller += bound_triangles(cells.leaf_triangles, leaves).size() < scene.triangle_count();
    if (bound != BspBound::None) {
      EXPECT_GT(smaller, 0u);
    }
    for (uint32_t c = 0; c < cells.layout.cell_count(); ++c) {
      const std::vector<uint32_t> got = cell_visibility(scene, cells, c, ro).triangles;
      if (bound == BspBound::None)
        want.push_back(got);
      else
        EXPECT_EQ(got, want.at(c)) << "leaf " << co.leaves[c] << " bound " << int(bound);
    }
  }
}
