// Tests of view cells: grid layout and eye band, walkable placement (floor only, slope limit,
// winding, levels, headroom), boundary segments, and "from this cell A is seen, B is not".
#include "vislib/bake/view_cells.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/free_space.h"
#include "vislib/scene/import.h"

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

// --- Reachable walkable cells (walkable_reach.h) -------------------------------------------------

namespace {

// A closed room: a box whose faces point inwards (its floor faces up, its ceiling down).
void add_room(Scene& s, Vec3 lo, Vec3 hi) {
  const size_t first = s.triangles.size();
  add_box(s, lo, hi);
  for (size_t t = first; t < s.triangles.size(); ++t)
    std::swap(s.triangles[t][1], s.triangles[t][2]);
}

// A closed level: a shell [-1, 21] x [0, 12] x [-1, 21] whose roof (y = 12) faces up outside,
// around a room [0, 20] x [1, 11] x [0, 20] (floor y = 1); in the room, a platform 4 m high
// (top y = 5, over [3, 7] x [3, 7]: more than a step) and a low one 0.3 m high (top y = 1.3,
// over [15, 19] x [15, 19]: one step). Columns of 2 start at -1: the platforms cover whole ones.
Scene closed_level() {
  Scene s;
  add_box(s, {-1, 0, -1}, {21, 12, 21});
  add_room(s, {0, 1, 0}, {20, 11, 20});
  add_box(s, {3, 1, 3}, {7, 5, 7});
  add_box(s, {15, 1, 15}, {19, 1.3, 19});
  return s;
}

// Cells of `c` by the floor level they stand on (their bottom is the floor + 1.5).
struct LevelCounts {
  size_t roof = 0, platform = 0, floor = 0, other = 0;
};
LevelCounts level_counts(const ViewCells& c) {
  LevelCounts n;
  for (const auto& b : c.layout.boxes) {
    if (b.min[1] == 12 + 1.5)
      ++n.roof;
    else if (b.min[1] == 5 + 1.5)
      ++n.platform;
    else if (b.min[1] == 1 + 1.5)
      ++n.floor;
    else
      ++n.other;
  }
  return n;
}

WalkableOptions closed_level_options(std::vector<Vec3> starts) {
  WalkableOptions o;
  o.cell_size = 2;
  o.agent = {1.8, 0.45, 0.45};
  for (Vec3 p : starts) o.starts.push_back({p, "test"});
  return o;
}

}  // namespace

TEST(WalkableReach, RoofOutsideAClosedLevelGetsCellsOnlyWithoutAStart) {
  const Scene s = closed_level();
  const LevelCounts all = level_counts(walkable_cells(s, closed_level_options({})));
  EXPECT_EQ(all.roof, 11u * 11u);  // the shell's roof: every column
  EXPECT_EQ(all.platform, 4u);
  EXPECT_EQ(all.floor, 11u * 11u - 4u);  // not under the high platform (no headroom)
  EXPECT_EQ(all.other, 0u);
  const LevelCounts kept = level_counts(walkable_cells(s, closed_level_options({{10, 2, 10}})));
  EXPECT_EQ(kept.roof, 0u);
  EXPECT_EQ(kept.floor, all.floor);  // the room's floor and the low platform, one step up
}

TEST(WalkableReach, PlatformsHigherThanAStepAreDroppedUnlessAStartIsOnThem) {
  const Scene s = closed_level();
  const LevelCounts all = level_counts(walkable_cells(s, closed_level_options({})));
  const LevelCounts from_floor =
      level_counts(walkable_cells(s, closed_level_options({{10, 2, 10}})));
  EXPECT_EQ(from_floor.platform, 0u);
  // From the platform's top the agent drops onto the floor: both are kept, the roof is not.
  const LevelCounts from_top = level_counts(walkable_cells(s, closed_level_options({{5, 6, 5}})));
  EXPECT_EQ(from_top.platform, all.platform);
  EXPECT_EQ(from_top.floor, all.floor);
  EXPECT_EQ(from_top.roof, 0u);
  // A step as high as the platform climbs it.
  WalkableOptions climb = closed_level_options({{10, 2, 10}});
  climb.agent.step = 4.1;
  EXPECT_EQ(level_counts(walkable_cells(s, climb)).platform, all.platform);
}

TEST(WalkableReach, AgentTallerThanTheRoomReachesNothingAndNarrowFloorIsNotStoodOn) {
  const Scene s = closed_level();
  WalkableOptions tall = closed_level_options({{10, 2, 10}});
  tall.agent.height = 10.5;  // the room is 10 high
  EXPECT_THROW(walkable_cells(s, tall), PlacementError);
  // A ledge 0.4 wide (a shelf on the wall, 1.2 up: reached from a start on it) is narrower
  // than an agent of radius 0.45 but not than one of radius 0.1.
  Scene shelf = closed_level();
  add_box(shelf, {0, 3.2, 9}, {0.4, 3.4, 13});
  WalkableOptions wide = closed_level_options({{0.2, 4, 11}});
  wide.required_starts = false;
  wide.starts.push_back({{10, 2, 10}, "test"});
  auto shelf_cells = [&](const WalkableOptions& o) {
    size_t n = 0;
    for (const auto& b : walkable_cells(shelf, o).layout.boxes) n += b.min[1] == 3.4 + 1.5;
    return n;
  };
  EXPECT_EQ(shelf_cells(wide), 0u);
  WalkableOptions thin = wide;
  thin.agent.radius = 0.1;
  EXPECT_EQ(shelf_cells(thin), 2u);
}

TEST(WalkableReach, StartWithoutFloorIsRefusedOrLeftOutAndRecorded) {
  const Scene s = closed_level();
  WalkableOptions o = closed_level_options({{10, -5, 10}});  // under the level
  try {
    walkable_cells(s, o);
    ADD_FAILURE() << "no error";
  } catch (const PlacementError& e) {
    EXPECT_EQ(e.problem(), PlacementProblem::StartWithoutFloor);
    EXPECT_NE(std::string(e.what()).find("10,-5,10"), std::string::npos) << e.what();
  }
  o.required_starts = false;
  EXPECT_THROW(walkable_cells(s, o), PlacementError);  // no start has floor
  o.starts.push_back({{10, 2, 10}, "second"});
  const ViewCells c = walkable_cells(s, o);
  EXPECT_EQ(level_counts(c).roof, 0u);
  const auto d = nlohmann::json::parse(c.description);
  ASSERT_EQ(d["starts"].size(), 2u);
  EXPECT_TRUE(d["starts"][0]["floor"].is_null());
  // The floor as voxelized: rounded up by at most a voxel height (0.225).
  EXPECT_NEAR(d["starts"][1]["floor"].get<double>(), 1.0 + 0.1125, 0.1125);
  EXPECT_EQ(d["starts"][1]["source"], "second");
}

TEST(WalkableReach, DescriptionRecordsTheRuleTheAgentAndTheStarts) {
  const Scene s = closed_level();
  const auto none = nlohmann::json::parse(walkable_cells(s, closed_level_options({})).description);
  EXPECT_EQ(none["rule"], "every floor level with headroom");
  EXPECT_FALSE(none.contains("starts"));
  const auto d =
      nlohmann::json::parse(walkable_cells(s, closed_level_options({{10, 2, 10}})).description);
  EXPECT_NE(d["rule"].get<std::string>().find("reachable from the starts"), std::string::npos);
  EXPECT_EQ(d["agent"]["height"], 1.8);
  EXPECT_EQ(d["agent"]["radius"], 0.45);
  EXPECT_EQ(d["agent"]["step"], 0.45);
  EXPECT_EQ(d["starts"][0]["point"], nlohmann::json({10, 2, 10}));
  EXPECT_GT(d["voxel"]["side"].get<double>(), 0);
}

TEST(WalkableReach, SameInputsGiveTheSameCells) {
  const Scene s = closed_level();
  const WalkableOptions o = closed_level_options({{5, 6, 5}, {10, 2, 10}});
  const ViewCells a = walkable_cells(s, o), b = walkable_cells(s, o);
  EXPECT_EQ(a.description, b.description);
  ASSERT_EQ(a.layout.boxes.size(), b.layout.boxes.size());
  for (size_t k = 0; k < a.layout.boxes.size(); ++k)
    EXPECT_TRUE(a.layout.boxes[k] == b.layout.boxes[k]) << k;
}

TEST(WalkableReach, ClockwiseFrontFacesFindTheSameFloorsWhenTheWindingIsReversed) {
  // A Quake map's faces are wound clockwise seen from the front: the same level with every
  // triangle reversed, read with clockwise_front, gives the same cells.
  const Scene s = closed_level();
  Scene reversed = s;
  for (auto& t : reversed.triangles) std::swap(t[1], t[2]);
  WalkableOptions o = closed_level_options({{10, 2, 10}});
  const ViewCells a = walkable_cells(s, o);
  EXPECT_THROW(walkable_cells(reversed, o), PlacementError);  // read counter-clockwise: no floor
  o.clockwise_front = true;
  const ViewCells b = walkable_cells(reversed, o);
  ASSERT_EQ(a.layout.boxes.size(), b.layout.boxes.size());
  for (size_t k = 0; k < a.layout.boxes.size(); ++k)
    EXPECT_TRUE(a.layout.boxes[k] == b.layout.boxes[k]) << k;
}

TEST(WalkableReach, PlacementDefaultsTheAgentFromTheEyeBandAndRefusesABadOne) {
  const Scene s = closed_level();
  CellPlacement p;
  p.walkable = true;
  p.starts = {{{10, 2, 10}, "test"}};
  const auto d = nlohmann::json::parse(place_view_cells(s, p).description);
  EXPECT_EQ(d["agent"]["height"], 1.8);
  EXPECT_EQ(d["agent"]["radius"], 0.45);
  EXPECT_EQ(d["agent"]["step"], 0.45);
  p.agent_step = -1;
  try {
    place_view_cells(s, p);
    ADD_FAILURE() << "no error";
  } catch (const PlacementError& e) {
    EXPECT_EQ(e.problem(), PlacementProblem::BadAgent);
  }
}

// The level as an OBJ file, for the command line.
namespace {
std::string closed_level_obj() {
  static const std::string path = [] {
    const Scene s = closed_level();
    std::string p = vislib_test::temp_dir("walkable_reach_obj") + "/level.obj";
    std::ofstream out(p);
    for (const Vec3& v : s.positions[0]) out << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    for (const auto& t : s.triangles)
      out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    return p;
  }();
  return path;
}
}  // namespace

TEST(WalkableReach, CliKeepsOnlyReachableCellsAndRefusesBadStartsWithExitTwo) {
  const std::string base = "bake " + closed_level_obj() + " --walkable --cell-size 2 --dry-run ";
  std::string out;
  ASSERT_EQ(vislib_test::run_pvs(base + "-o x.pvs", &out), 0) << out;
  const size_t all = std::stoul(out);
  ASSERT_EQ(vislib_test::run_pvs(base + "--walkable-from 10,2,10 -o x.pvs", &out), 0) << out;
  EXPECT_EQ(std::stoul(out), all - 11 * 11 - 4) << out;  // no roof, no platform top
  ASSERT_EQ(
      vislib_test::run_pvs(base + "--walkable-from 10,2,10 --walkable-from 5,6,5 -o x.pvs", &out),
      0)
      << out;
  EXPECT_EQ(std::stoul(out), all - 11 * 11) << out;
  ASSERT_EQ(vislib_test::run_pvs(base + "--walkable-from none -o x.pvs", &out), 0) << out;
  EXPECT_EQ(std::stoul(out), all) << out;  // every floor level, as without a start
  EXPECT_EQ(
      vislib_test::run_pvs(base + "--walkable-from none --walkable-from 1,2,3 -o x.pvs", &out), 2)
      << out;
  EXPECT_NE(out.find("'none' alone"), std::string::npos) << out;
  for (const char* bad : {"1,2", "1,2,3,4", "a,b,c", "nan,0,0", "1,inf,3", ""}) {
    EXPECT_EQ(vislib_test::run_pvs(base + "--walkable-from '" + bad + "' -o x.pvs", &out), 2)
        << bad << "\n"
        << out;
    EXPECT_NE(out.find("--walkable-from"), std::string::npos) << out;
    EXPECT_NE(out.find("expected x,y,z"), std::string::npos) << out;
  }
  EXPECT_EQ(vislib_test::run_pvs(base + "--walkable-from 10,-50,10 -o x.pvs", &out), 2) << out;
  EXPECT_NE(out.find("10,-50,10 (--walkable-from) has no walkable floor under it"),
            std::string::npos)
      << out;
  EXPECT_EQ(vislib_test::run_pvs("bake " + closed_level_obj() +
                                     " --box 0,0,0,20,12,20 --grid 1,1,1 --walkable-from 1,2,3 "
                                     "--dry-run -o x.pvs",
                                 &out),
            2)
      << out;
  EXPECT_NE(out.find("--walkable-from: only applies with --walkable"), std::string::npos) << out;
  EXPECT_EQ(vislib_test::run_pvs(base + "--walkable-from 10,2,10 --agent-height 0 -o x.pvs", &out),
            2)
      << out;
}

// fdm6 (Sauerbraten units, eyes 12-16 up, docs/bake.md): a basin whose outer walls' tops form a
// ring at y = 144 (208 on one side), the roof of the map's shell. From a start in the basin no
// cell stands on them.
TEST(WalkableReachRealScenes, Fdm6KeepsNoCellOnTheShellsRoof) {
  VISLIB_REQUIRE_SHARED(shared);
  const Scene s = load_scene(shared + "/scenes/sauer_fdm6/fdm6.obj");
  CellPlacement p;
  p.walkable = true;
  p.cell_size = 16;
  p.eye = EyeBand{12, 16};
  auto on_roof = [](const ViewCells& c) {
    size_t n = 0;
    for (const auto& b : c.layout.boxes) n += b.min[1] - 12 >= 144;
    return n;
  };
  const ViewCells all = place_view_cells(s, p);
  EXPECT_EQ(all.layout.cell_count(), 1266u);
  EXPECT_GT(on_roof(all), 200u);
  p.starts = {{{-16, 20, -16}, "basin"}};
  const ViewCells kept = place_view_cells(s, p);
  EXPECT_EQ(on_roof(kept), 0u);
  EXPECT_LT(kept.layout.cell_count(), all.layout.cell_count());
  for (const auto& b : kept.layout.boxes) EXPECT_LT(b.max[1], 144.0);
}
