// Tests of view cells: grid layout and eye band, walkable placement (floor only, slope limit,
// winding, levels, headroom), boundary segments, and "from this cell A is seen, B is not".
#include "vislib/bake/view_cells.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <optional>

#include "tests/scene_builders.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/free_space.h"

using namespace vislib;
using vislib_test::add_quad;

namespace {

// A closed box with outward (counter-clockwise seen from outside) faces, one object per face.
void add_box(Scene& s, Vec3 lo, Vec3 hi) {
  double x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
  add_quad(s, {x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // bottom, facing -y
  add_quad(s, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0});  // top, +y
  add_quad(s, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0});  // -x
  add_quad(s, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});  // +x
  add_quad(s, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0});  // -z
  add_quad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // +z
}

// An upward-facing floor quad over [x0,x1] x [z0,z1] at height y.
void add_floor(Scene& s, double x0, double x1, double z0, double z1, double y) {
  add_quad(s, {x0, y, z0}, {x0, y, z1}, {x1, y, z1}, {x1, y, z0});
}

// Floor 10 x 10 at y = 0, a 4 x 4 x 5 box standing on it at the corner, and a 60-degree ramp
// beside the floor (x 10..12, z 0..2).
Scene test_level() {
  Scene s;
  add_floor(s, 0, 10, 0, 10, 0);
  add_box(s, {0, 0, 0}, {4, 5, 4});
  double h = 2 * std::tan(60 * M_PI / 180);
  add_quad(s, {10, 0, 0}, {10, 0, 2}, {12, h, 2}, {12, h, 0});
  return s;
}

size_t cells_with_bottom(const ViewCells& c, double y) {
  size_t n = 0;
  for (const auto& b : c.layout.boxes) n += b.min[1] == y;
  return n;
}

}  // namespace

TEST(ViewCells, GridCellsTileTheBoxAndCarryTheEyeBand) {
  Box3 box;
  box.extend({-10, 0, -5});
  box.extend({10, 6, 5});
  ViewCells c = grid_cells(box, 4, 2, 2, EyeBand{1.5, 1.8});
  ASSERT_EQ(c.layout.cell_count(), 16u);
  pvs::Box b = c.layout.cell_box(4 + 1);  // i = 1, j = 1, k = 0
  EXPECT_EQ(b.min[0], -5);
  EXPECT_EQ(b.max[0], 0);
  EXPECT_EQ(b.min[1], 3);
  EXPECT_EQ(b.max[1], 6);
  pvs::Box v = c.layout.view_region(5);
  EXPECT_EQ(v.min[1], 4.5);
  EXPECT_EQ(v.max[1], 4.8);
  EXPECT_EQ(v.min[0], b.min[0]);
  // Without a band the view region is the cell.
  ViewCells whole = grid_cells(box, 4, 2, 2);
  EXPECT_TRUE(whole.layout.view_region(5) == whole.layout.cell_box(5));
  // By size: ceil(extent / size) cells per axis.
  EXPECT_EQ(grid_cells_by_size(box, 3).layout.cell_count(), 7u * 2 * 4);
}

TEST(ViewCells, WalkableCellsOnlyWhereThereIsFloor) {
  Scene s = test_level();
  WalkableOptions o;
  o.cell_size = 2;
  ViewCells c = walkable_cells(s, o);
  // 25 floor columns; the 4 under the box have no headroom, the box's roof gives 4 cells at 5 m;
  // the ramp is too steep; the columns beside the floor (x 10..12) have no floor.
  EXPECT_EQ(cells_with_bottom(c, 1.5), 21u);
  EXPECT_EQ(cells_with_bottom(c, 6.5), 4u);
  EXPECT_EQ(c.layout.cell_count(), 25u);
  for (const auto& b : c.layout.boxes) {
    EXPECT_LE(b.max[0], 10.0);
    EXPECT_NEAR(b.max[1] - b.min[1], 0.3, 1e-12);
    EXPECT_EQ(b.max[0] - b.min[0], 2.0);
  }
  // Cell order: columns by z, then x; levels bottom to top. The first column is under the box.
  EXPECT_EQ(c.layout.boxes[0].min[1], 6.5);
  EXPECT_EQ(c.layout.boxes[0].min[0], 0.0);
  EXPECT_EQ(c.layout.boxes[2].min[0], 4.0);
}

TEST(ViewCells, SlopeLimitDecidesWhatIsFloor) {
  Scene s = test_level();
  WalkableOptions o;
  o.cell_size = 2;
  o.max_slope_degrees = 70;  // the 60-degree ramp is floor now
  ViewCells c = walkable_cells(s, o);
  EXPECT_EQ(c.layout.cell_count(), 26u);
  const pvs::Box& ramp = c.layout.boxes[5];  // column (i 5, k 0), after 4 floor columns + 1 roof
  EXPECT_EQ(ramp.min[0], 10.0);
  EXPECT_NEAR(ramp.min[1], 1.5, 1e-12);                                 // ramp's low end
  EXPECT_NEAR(ramp.max[1], 2 * std::tan(60 * M_PI / 180) + 1.8, 1e-9);  // its high end
}

TEST(ViewCells, HeadroomCanBeSwitchedOff) {
  WalkableOptions o;
  o.cell_size = 2;
  o.require_headroom = false;
  EXPECT_EQ(walkable_cells(test_level(), o).layout.cell_count(), 29u);
}

TEST(ViewCells, DownwardFacingTrianglesAreNotFloor) {
  Scene s;
  add_quad(s, {0, 0, 0}, {4, 0, 0}, {4, 0, 4}, {0, 0, 4});  // clockwise seen from above
  EXPECT_EQ(walkable_cells(s, WalkableOptions{}).layout.cell_count(), 0u);
}

TEST(ViewCells, FloorsCloserThanTheEyeBandMergeIntoOneLevel) {
  Scene s;
  add_floor(s, 0, 2, 0, 2, 0);
  add_floor(s, 0, 2, 0, 1, 0.4);  // a step 0.4 m up in the same column
  add_floor(s, 0, 2, 0, 2, 3.0);  // a floor above, more than 1.8 m higher: its own level
  WalkableOptions o;
  o.cell_size = 2;
  o.require_headroom = false;
  ViewCells c = walkable_cells(s, o);
  ASSERT_EQ(c.layout.cell_count(), 2u);
  EXPECT_EQ(c.layout.boxes[0].min[1], 1.5);
  EXPECT_EQ(c.layout.boxes[0].max[1], 0.4 + 1.8);
  EXPECT_EQ(c.layout.boxes[1].min[1], 4.5);
}

TEST(ViewCells, ClipBoxLimitsTheCells) {
  WalkableOptions o;
  o.cell_size = 2;
  Box3 clip;
  clip.extend({4, -1, 4});
  clip.extend({8, 1, 8});
  o.clip = clip;
  ViewCells c = walkable_cells(test_level(), o);
  EXPECT_EQ(c.layout.cell_count(), 4u);  // 2 x 2 columns, ground only (the roof at 5 m is outside)
}

TEST(ViewCells, BoundarySegmentsAreTheBottomAndTopRectangles) {
  Box3 r;
  r.extend({0, 1.5, 0});
  r.extend({2, 1.8, 3});
  auto segs = cell_boundary_segments(r);
  ASSERT_EQ(segs.size(), 8u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(segs[i].from.y, 1.5);
    EXPECT_EQ(segs[i].to.y, 1.5);
    EXPECT_EQ(segs[4 + i].from.y, 1.8);
  }
  r.max.y = 1.5;
  EXPECT_EQ(cell_boundary_segments(r).size(), 4u);
}

TEST(ViewCells, CellSeesWhatIsOnItsSideOfTheWallOnly) {
  Scene s;
  add_floor(s, 1, 3, 1, 3, 0.5);    // A: objects 0, triangles 0-1
  add_floor(s, 17, 19, 1, 3, 0.5);  // B: object 1, triangles 2-3
  add_box(s, {9, 0, -100}, {10, 10, 100});
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({21, 2, 4});
  ViewCells c = grid_cells(box, 3, 1, 1, EyeBand{1.5, 1.8});
  RegionOptions o;
  o.segment.resolution = 64;
  o.runs = 2;
  auto seen = [&](uint32_t cell, uint32_t tri) {
    auto v = cell_visibility(s, c.layout, cell, o).triangles;
    return std::binary_search(v.begin(), v.end(), tri);
  };
  EXPECT_TRUE(seen(0, 0));
  EXPECT_FALSE(seen(0, 2));
  EXPECT_TRUE(seen(2, 2));
  EXPECT_FALSE(seen(2, 0));
  EXPECT_EQ(cell_visibility(s, c.layout, 0, o).segments.size(), 8u);
}

TEST(ViewCells, CellVisibilityIsTheSameWithOneAndTwoThreads) {
  Scene s = test_level();
  WalkableOptions w;
  w.cell_size = 4;
  ViewCells c = walkable_cells(s, w);
  RegionOptions o;
  o.segment.resolution = 32;
  o.runs = 3;
  o.seed = 7;
  std::vector<std::vector<uint32_t>> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    for (uint32_t k = 0; k < c.layout.cell_count(); ++k)
      one.push_back(cell_visibility(s, c.layout, k, o).triangles);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    for (uint32_t k = 0; k < c.layout.cell_count(); ++k)
      two.push_back(cell_visibility(s, c.layout, k, o).triangles);
  }
  EXPECT_EQ(one, two);
  EXPECT_NE(cell_seed(7, 0), cell_seed(7, 1));
}

// A walkable column that straddles a building holds points inside it.
TEST(ViewCellsFreeSpace, PointInsideClosedBoxIsEnclosedAndStreetPointIsNot) {
  Scene s = test_level();  // floor 10 x 10, box 4 x 5 x 4 at the corner
  EXPECT_TRUE(point_enclosed(s, {2, 1.6, 2}));
  EXPECT_FALSE(point_enclosed(s, {7, 1.6, 7}));  // sees the sky
  EXPECT_FALSE(point_enclosed(s, {2, 6.0, 2}));  // above the roof
}

TEST(ViewCellsFreeSpace, UnderARoofFrontFacesAreNotEnclosure) {
  // A floor and a downward-facing roof over it: rays up hit the roof's front face, rays
  // sideways escape; the point is free.
  Scene s;
  add_floor(s, -5, 5, -5, 5, 0);
  add_quad(s, {-5, 3, -5}, {5, 3, -5}, {5, 3, 5}, {-5, 3, 5});  // facing -y
  EXPECT_FALSE(point_enclosed(s, {0, 1.6, 0}));
}

TEST(ViewCellsFreeSpace, CellStraddlingABuildingGivesAFreePointOutsideIt) {
  Scene s = test_level();
  // A cell over x 0..6, z 0..6: its centre (3, 1.65, 3) is inside the box (0..4), the samples
  // beyond x or z = 4 are free.
  Box3 region;
  region.min = {0, 1.5, 0};
  region.max = {6, 1.8, 6};
  CellFreeSpace f = cell_free_space(s, region);
  EXPECT_EQ(f.samples, 17);
  EXPECT_TRUE(f.centre_enclosed);
  EXPECT_GT(f.enclosed, 0);
  EXPECT_LT(f.enclosed, f.samples);
  ASSERT_TRUE(f.free_point.has_value());
  EXPECT_FALSE(point_enclosed(s, *f.free_point));
  EXPECT_TRUE(f.free_point->x > 4 || f.free_point->z > 4);
  // A cell wholly in the street: centre free, nothing enclosed.
  region.min = {6, 1.5, 6};
  region.max = {10, 1.8, 10};
  f = cell_free_space(s, region);
  EXPECT_FALSE(f.centre_enclosed);
  EXPECT_EQ(f.enclosed, 0);
  EXPECT_EQ(*f.free_point, (Vec3{8, 1.65, 8}));
}

// place_view_cells (pvs bake's placement options, checked in the library).
TEST(CellPlacement, GridByCountsBySizeAndWalkableGiveTheDirectPlacements) {
  const Scene s = test_level();
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({10, 3, 10});
  CellPlacement p;
  p.box = box;
  p.grid = std::array<uint32_t, 3>{2, 1, 5};
  p.eye = EyeBand{1.5, 1.8};
  const ViewCells counts = place_view_cells(s, p);
  const ViewCells direct = grid_cells(box, 2, 1, 5, EyeBand{1.5, 1.8});
  ASSERT_EQ(counts.layout.cell_count(), 10u);
  for (uint32_t c = 0; c < 10; ++c)
    EXPECT_TRUE(counts.layout.view_region(c) == direct.layout.view_region(c)) << c;
  p.grid.reset();
  p.cell_size = 4;  // ceil(10/4) * ceil(3/4) * ceil(10/4)
  EXPECT_EQ(place_view_cells(s, p).layout.cell_count(), 3u * 1 * 3);
  CellPlacement w;
  w.walkable = true;  // cell size 0: columns of 2
  WalkableOptions wo;
  wo.cell_size = 2;
  EXPECT_EQ(place_view_cells(s, w).layout.boxes.size(), walkable_cells(s, wo).layout.boxes.size());
  EXPECT_GT(place_view_cells(s, w).layout.cell_count(), 0u);
}

TEST(CellPlacement, InconsistentPlacementsAreRefusedWithTheirProblem) {
  const Scene s = test_level();
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({10, 3, 10});
  auto problem = [&](const CellPlacement& p) {
    try {
      place_view_cells(s, p);
    } catch (const PlacementError& e) {
      return std::optional<PlacementProblem>(e.problem());
    }
    return std::optional<PlacementProblem>();
  };
  CellPlacement p;
  p.walkable = true;
  p.grid = std::array<uint32_t, 3>{1, 1, 1};
  EXPECT_EQ(problem(p), PlacementProblem::GridWithWalkable);
  p = {};
  p.walkable = true;
  p.cell_size = 1e-4;  // 10 / 1e-4 = 1e5 columns per side: 1e10 columns
  EXPECT_EQ(problem(p), PlacementProblem::TooManyColumns);
  p = {};
  p.cell_size = 1;
  EXPECT_EQ(problem(p), PlacementProblem::NoBox);
  p.box = box;
  p.grid = std::array<uint32_t, 3>{1, 1, 1};
  EXPECT_EQ(problem(p), PlacementProblem::GridAndCellSize);
  p.cell_size = 0;
  p.grid = std::array<uint32_t, 3>{1000, 100, 101};  // 1.01e7
  EXPECT_EQ(problem(p), PlacementProblem::TooManyGridCells);
  p.grid.reset();
  EXPECT_EQ(problem(p), PlacementProblem::NoGridNorCellSize);
  p.cell_size = 0.004;  // 2500 * 750 * 2500 cells
  EXPECT_EQ(problem(p), PlacementProblem::TooManySizedCells);
}
