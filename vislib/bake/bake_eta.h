// bake_eta.h: the ETA of a bake, with the cells still to bake weighted by their expected work
// instead of counted alike.
//
// A cell's kernel work is its from-segment runs (view_cells.h: K runs on each perimeter segment of
// the bottom and top rectangles of its eye band). A run costs a fixed part (a pass over the
// scene's triangles or the BVH per face, the tiles' set-up) and a part that grows with its
// length (the pieces swept by the moving eye); with shared edges (BakeSettings::share_segments)
// run 0 of an edge common to several cells is computed once, by the first of them in cell order
// (the pipeline hands cells out in that order), and the others get it for nothing. Counting cells
// alike therefore errs both ways: the first cells of a grid compute every edge of their rectangles
// and later ones about half, and cells of unequal size (clipped columns, tall eye bands over
// stairs) cost unequal work. The weights below follow that model; they know nothing of the
// scene's content (a cell that sees more pieces per pixel costs more per metre), which the rate
// measured on the cells already baked carries over to the rest.
#pragma once

#include <cstdint>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/kernel/region_visibility.h"

namespace vislib {

// The fixed part of a run's expected work, as a multiple of the length of the layout's mean
// perimeter segment: a run of length l weighs l + kRunFixedEdges * mean. Unitless (a model
// constant, not a measured one: 1 says a run of a typical edge spends as much on its fixed part as
// on its length; tests/data/bake_cell_seconds_city.txt replays a real bake against it).
constexpr double kRunFixedEdges = 1.0;

// The expected kernel work of each cell of `layout` (indexed by cell id), in units of one run of
// the mean perimeter segment's length. Cells with bake[c] == 0 (another shard's, or recovered
// from a checkpoint) weigh 0 and compute no shared run. `runs` (>= 1) orientations per segment;
// with `share_segments`, run 0 of a segment used by several cells to bake (the same end points,
// bit for bit) counts once, for the first of them by cell id. Long segments are not modelled
// apart: each edge of a chain counts for the first cell that uses it. bake.size() must equal
// layout.cell_count(). Deterministic; O(cells log cells).
std::vector<double> expected_cell_work(const pvs::CellLayout& layout,
                                       const std::vector<uint8_t>& bake, int runs,
                                       bool share_segments);

// The same for cells given by their segments (segments[c]: every segment cell c runs, such as
// cell_segment_groups gives; the mean is over these). bake.size() must equal segments.size().
std::vector<double> expected_cell_work(const std::vector<std::vector<Segment>>& segments,
                                       const std::vector<uint8_t>& bake, int runs,
                                       bool share_segments);

// Seconds left when `done` units of work took `elapsed` seconds and `left` units remain:
// elapsed * left / done. NaN when done <= 0 (no rate yet); 0 when left <= 0. Units of work are
// the caller's (cells, or expected_cell_work's) as long as done and left share them.
double eta_seconds(double elapsed, double done, double left);

}  // namespace vislib
