// Tests of the bake's ETA (bake_eta.h): the expected work of cells counted by hand on a small
// grid, and the weighted ETA replayed against the per-cell kernel seconds recorded from a real
// bake (tests/data/bake_cell_seconds_city.txt, and bake_cell_seconds_fdm6.txt of a shared real
// level): its error must be smaller than the one of counting cells alike. No timing is measured.
#include "vislib/bake/bake_eta.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_support.h"
#include "vislib/bake/view_cells.h"
#include "vislib/scene/import.h"

using namespace vislib;

namespace {

// nx x 1 x 1 square cells of side 10 (y 0..3), eye band 1.5..1.8: two rectangles of four
// perimeter segments of length 10 each, so every run weighs 1 unit.
pvs::CellLayout row_of_cells(uint32_t nx) {
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({10.0 * nx, 3, 10});
  return grid_cells(box, nx, 1, 1, EyeBand{1.5, 1.8}).layout;
}

TEST(BakeEta, SharedEdgesCountForTheFirstCellThatBakesThem) {
  const pvs::CellLayout row = row_of_cells(3);
  // Alone, a cell runs 2 rectangles x 4 segments.
  EXPECT_EQ(expected_cell_work(row, {1, 1, 1}, 1, false), (std::vector<double>{8, 8, 8}));
  // Shared: cells 1 and 2 get the edge (one per rectangle) their left neighbour computed.
  EXPECT_EQ(expected_cell_work(row, {1, 1, 1}, 1, true), (std::vector<double>{8, 6, 6}));
  // K = 3: runs 1 and 2 of every segment are the cell's own.
  EXPECT_EQ(expected_cell_work(row, {1, 1, 1}, 3, true), (std::vector<double>{24, 22, 22}));
  // A cell not baked (another shard's, or resumed) computes nothing for its neighbours.
  EXPECT_EQ(expected_cell_work(row, {0, 1, 0}, 1, true), (std::vector<double>{0, 8, 0}));
  EXPECT_EQ(expected_cell_work(row, {1, 0, 1}, 1, true), (std::vector<double>{8, 0, 8}));
}

TEST(BakeEta, LongerRunsWeighMoreWithTheFixedPartOfARun) {
  // One cell of 10 x 30: four segments of lengths 10, 10, 30, 30 per rectangle, mean 20; a run
  // weighs (l + kRunFixedEdges * 20) / (20 + kRunFixedEdges * 20).
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({10, 3, 30});
  const pvs::CellLayout one = grid_cells(box, 1, 1, 1, EyeBand{1.5, 1.8}).layout;
  const double f = kRunFixedEdges * 20, unit = 20 + f;
  const double expected = 2 * (2 * (10 + f) + 2 * (30 + f)) / unit;
  EXPECT_NEAR(expected_cell_work(one, {1}, 1, true)[0], expected, 1e-12);
  EXPECT_NEAR(expected, 8.0, 1e-12);  // the mean run weighs 1
}

TEST(BakeEta, EtaIsElapsedTimesWorkLeftOverWorkDone) {
  EXPECT_DOUBLE_EQ(eta_seconds(10, 2, 6), 30);
  EXPECT_EQ(eta_seconds(10, 2, 0), 0);
  EXPECT_TRUE(std::isnan(eta_seconds(10, 0, 6)));
}

// Replays the per-cell CPU seconds recorded in tests/data/`file` for the cells of `layout`, cells
// finishing in cell order as on one thread, and checks at 10%, 25% and 50% of the cells that the
// ETA weighted by expected work errs less than the one counting cells alike.
void replay(const std::string& file, const pvs::CellLayout& layout) {
  std::ifstream in(std::string(VISLIB_SOURCE_DIR) + "/tests/data/" + file);
  ASSERT_TRUE(in) << file;
  std::vector<double> seconds;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    uint32_t cell;
    double t;
    ASSERT_TRUE(s >> cell >> t) << line;
    ASSERT_EQ(cell, seconds.size()) << line;
    seconds.push_back(t);
  }
  const uint32_t n = layout.cell_count();
  ASSERT_EQ(seconds.size(), n) << file;
  const std::vector<double> work = expected_cell_work(layout, std::vector<uint8_t>(n, 1), 1, true);
  double total = 0, total_work = 0;
  for (uint32_t c = 0; c < n; ++c) total += seconds[c], total_work += work[c];
  for (double fraction : {0.10, 0.25, 0.50}) {
    const uint32_t k = uint32_t(std::lround(fraction * n));
    double elapsed = 0, work_done = 0;
    for (uint32_t c = 0; c < k; ++c) elapsed += seconds[c], work_done += work[c];
    const double truth = total - elapsed;
    const double by_cells = eta_seconds(elapsed, k, n - k);
    const double by_work = eta_seconds(elapsed, work_done, total_work - work_done);
    std::printf(
        "%s: after %u of %u cells: %.2f s left, ETA by cells %.2f s (%+.0f%%), by work "
        "%.2f s (%+.0f%%)\n",
        file.c_str(), k, n, truth, by_cells, 100 * (by_cells / truth - 1), by_work,
        100 * (by_work / truth - 1));
    EXPECT_LT(std::abs(by_work - truth), std::abs(by_cells - truth)) << file << " at " << fraction;
  }
}

// The quick start's bake of data/city.glb (README).
TEST(BakeEta, WeightedEtaBeatsCountingCellsOnARecordedBake) {
  const Scene scene = load_scene(std::string(VISLIB_SOURCE_DIR) + "/data/city.glb");
  CellPlacement p;
  p.walkable = true;
  p.cell_size = 24;
  p.box = Box3{};
  p.box->extend({-120, -1, -120});
  p.box->extend({120, 1, 120});
  replay("bake_cell_seconds_city.txt", place_view_cells(scene, p).layout);
}

// A real level: the shared Sauerbraten arena fdm6 (skipped without ../shared).
TEST(BakeEta, WeightedEtaBeatsCountingCellsOnARealLevel) {
  VISLIB_REQUIRE_SHARED(shared);
  const std::string path = shared + "/scenes/sauer_fdm6/fdm6.obj";
  CellPlacement p;
  p.walkable = true;
  p.cell_size = 32;
  p.eye = EyeBand{12, 16};
  replay("bake_cell_seconds_fdm6.txt", place_view_cells(load_scene(path), p).layout);
}

}  // namespace
