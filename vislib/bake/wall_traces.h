// wall_traces.h: segments inside a box cell along the walls that cross its eye band.
//
// A box cell's runs are the perimeters of its view region's rectangles (cell_visibility.h), which
// is exact for what its eyes see past the region's sides at the rectangles' heights. A walkable
// cell's region is a column over floor, and a building, a pillar or a ledge may stand inside it.
// An eye next to such a wall sees, at grazing angles along it and past its edges, what the
// perimeter samples only coarsely: the view changes fastest there (measured on the quick start's
// city: of the 44 (cell, triangle) pairs `pvs check` found missing with three band levels, runs
// on these traces find 33). A wall's trace is where the wall crosses the middle of the eye band,
// moved off the wall to its front side by a clearance (so the wall occludes: an eye closer to a
// surface than the near distance would see through it), clipped to the cell's rectangle, and
// collinear pieces that touch joined into one segment (a quad wall's two triangles give one).
// Like the perimeter rule it samples: it adds runs where the view changes fastest, it does not
// make the set exact.
#pragma once

#include <cstddef>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A wall, for its trace: a triangle whose normal is at least this many degrees from vertical (a
// floor or a gentle ramp under the band is not a wall; the band's bottom is what sees past it).
constexpr double kWallTraceMinTiltDegrees = 45;
// The trace's distance from its wall's plane, in multiples of the bake's near distance: at 1 the
// near plane of an eye on the trace would touch the wall.
constexpr double kWallTraceClearanceFactor = 4;
// Pieces of a trace shorter than this fraction of the cell's longer side are dropped (a wall that
// only grazes the cell's rectangle): a run costs about the same whatever its length.
constexpr double kWallTraceMinLengthFraction = 1e-3;

struct WallTraceOptions {
  double clearance = 0.04;  // scene units, > 0: kWallTraceClearanceFactor times the near distance
  bool clockwise_front = false;  // a Quake map's winding (floor_triangle's rule)
  size_t state = 0;              // key state whose geometry is used
};

// The wall traces of every cell of `layout` (a grid or box list), one list per cell: at the middle
// height of the cell's view region, the trace of every wall triangle that crosses that height
// inside the region's x/z rectangle, offset by options.clearance to the triangle's front side (its
// normal's horizontal direction; the side the winding faces, as walkable floors are found) and
// clipped to the rectangle; pieces on one line that touch (within 1e-9 of the cell's side) joined,
// pieces shorter than kWallTraceMinLengthFraction of the side dropped. Segments at constant y, in
// the order of the scene's triangles (a joined segment at its first triangle's place).
// Deterministic whatever the thread count (TBB over cells).
std::vector<std::vector<Segment>> wall_traces(const Scene& scene, const pvs::CellLayout& layout,
                                              const WallTraceOptions& options);

// The same for one view region (what wall_traces gives a cell with that region).
std::vector<Segment> wall_traces(const Scene& scene, const Box3& view_region,
                                 const WallTraceOptions& options);

}  // namespace vislib
