// cell_visibility.h: a view cell's visible set.
//
// A cell's visible set (cell_visibility) is the union of from-segment runs on the perimeters of
// the view region's rectangles at the band's levels (the bottom and the top by default), with the
// region's vertical edges (together the box's twelve edges: the paper's perimeter heuristic,
// §4.1) and the traces of walls inside the cell where the cells carry them (ViewCells), each with
// K cube orientations (§4.5) seeded per cell; or, for
// cells that carry their own segments (ViewCells::segments: a BSP leaf's faces or portals swept,
// bsp_cells.h), the union of runs on those and of the cell's own triangles (ViewCells::own).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/vec.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The segments a box cell's visibility is computed on: the four sides of each rectangle of the
// view region at `levels` (>= 2) heights evenly spaced from its bottom (y = min.y) to its top
// (y = max.y), bottom first, each in the order of perimeter_segments; only the four of the bottom
// when the region is flat in y. The default is the bottom and the top (kPaperBandLevels).
std::vector<Segment> cell_boundary_segments(const Box3& view_region, int levels = kPaperBandLevels);

// The four vertical edges of a box cell's view region (ViewCells::vertical_edges), bottom to top,
// at (min.x, min.z), (max.x, min.z), (min.x, max.z), (max.x, max.z); none when it is flat in y.
std::vector<Segment> vertical_edge_segments(const Box3& view_region);

// The family of runs of a portal's adaptive sweep (SegmentRunCache::expect_family): its chords
// are the same for both of its leaves (run_cell_groups judges them by both sides), so a bake
// registers one user per leaf it computes. The key of the sweep's first polygon edge and its
// side normal (the same FaceSweep but for `side` on both leaves).
SegmentRunCache::Key sweep_family_key(const FaceSweep& sweep);

// Seed of cell `cell`'s runs for a bake seeded `seed`; the bottom rectangle's runs use
// Rng::derive(cell_seed, 0), the top's Rng::derive(cell_seed, 1).
uint64_t cell_seed(uint64_t seed, uint32_t cell);

struct CellVisibility {
  std::vector<uint32_t> triangles;  // visible triangle ids, sorted
  std::vector<uint32_t> spheres;    // visible sphere indices, sorted
  std::vector<Segment> segments;    // every group of cell_segment_groups, in order
  double seconds = 0;               // kernel seconds
};

// The rectangles whose perimeters cell_visibility runs: those of cell_boundary_segments (the
// bottom and top of the cell's view region, and levels - 2 between; one when it is flat in y).
std::vector<Box3> cell_rectangles(const pvs::CellLayout& layout, uint32_t cell,
                                  int levels = kPaperBandLevels);

// The segments box cell `cell` of a baked file ran on (pvs inspect): the perimeters of its band's
// rectangles at the levels the metadata records (band_levels_of), its vertical edges when it
// records them (vertical_edges_of), then, when it records wall traces (wall_traces_of) and
// `scene` (the scene baked) is given, the cell's wall traces.
std::vector<Segment> recorded_cell_segments(const pvs::FileInfo& info, uint32_t cell,
                                            const Scene* scene);

// The segments cell `cell`'s visibility is computed on, in groups: group g's runs are seeded
// Rng::derive(cell_seed(seed, cell), g) (segments_visibility). Cells with their own segments
// (cells.segments not empty): cells.segments[cell], one group. Otherwise the perimeter segments
// of each of cell_rectangles(cells.layout, cell, cells.band_levels), one group per rectangle,
// then the view region's vertical edges (ViewCells::vertical_edges) as one group, then the
// cell's wall traces (ViewCells::wall_traces), when it has any, as one group.
std::vector<std::vector<Segment>> cell_segment_groups(const ViewCells& cells, uint32_t cell);

// Visible triangles of cell `cell` of `layout` (a grid or box list: BSP leaf cells carry their
// segments, use the ViewCells overload below): region_visibility (options.runs orientations,
// options.segment settings) on the bottom and the top rectangle of the view region, united.
// Depends only on the scene, the view region, `options` and `cell` (not on the thread count).
// Thread-safe; parallel inside (TBB). `progress(fraction)`, if given, is called after each
// from-segment run with the fraction in (0, 1] of the cell's runs done (from the calling thread
// or a worker; never two calls at once).
CellVisibility cell_visibility(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress = {});

// The same on the segment groups of cell_segment_groups(cells, cell): segments_visibility on each
// group, united. Same contract (thread-safe, independent of the thread count).
CellVisibility cell_visibility(const Scene& scene, const ViewCells& cells, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress = {});

// A witness of a cell's visible set as one ray: the triangle, the eye on the cell's segment
// (segment: index into the concatenated groups of cell_segment_groups; t along it) and the unit
// direction through the centre of the witness pixel of the run that saw it (scene coordinates);
// for a triangle of ViewCells::own, its ray, with segment kOwnTriangleSegment.
constexpr size_t kOwnTriangleSegment = size_t(-1);
struct CellWitnessRay {
  uint32_t tri = 0;
  Vec3 eye, dir;
  size_t segment = 0;
  int run = 0;
  double t = 0;
};

// Re-runs cell `cell`'s from-segment runs as cell_visibility does (the same segment groups, seeds,
// orientations and options) with witnesses (segment_visibility.h), and returns the witness rays
// of those of `wanted` (sorted triangle ids) that a run sees, or that are the cell's own
// (ViewCells::own), in increasing id; an id no run sees has none. Group by group, stopping once
// every wanted id has one, so the cost is at most that of cell_visibility with witnesses.
// options.shared_runs must be null. Deterministic, thread-safe.
std::vector<CellWitnessRay> cell_witness_rays(const Scene& scene, const ViewCells& cells,
                                              uint32_t cell, const RegionOptions& options,
                                              const std::vector<uint32_t>& wanted);

}  // namespace vislib
