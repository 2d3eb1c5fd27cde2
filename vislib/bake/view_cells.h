// view_cells.h: where the view cells of a bake are, and the boundary a cell's visibility is
// computed on.
//
// Two placements:
//  (a) a user grid over a box (grid_cells), with an optional eye-height band above each cell's
//      bottom face;
//  (b) automatic cells over walkable surfaces (walkable_cells): upward-facing triangles within a
//      slope limit are floor; the scene is cut into square columns of a given size (in x and z;
//      y is up) and a cell is placed in a column only where there is floor in it, one per floor
//      level, spanning the eye-height band above that floor (like Unreal's precomputed
//      visibility cells, which are placed over the surfaces of the level).
// Both give a pvs::CellLayout, the form the PVS file stores, so a cell's view region is the same
// whether computed at bake time or read back from the file (pvs::CellLayout::view_region).
//
// A cell's visible set: cell_visibility.h; points of a cell inside the geometry: free_space.h.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/face_sweep.h"
#include "vislib/bake/walkable_reach.h"
#include "vislib/bake/wall_traces.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/quake_bsp_volumes.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The cells of a bake and a JSON object (text) saying how they were placed, for the metadata of
// the PVS file.
// The eye band's rectangles of the paper's perimeter rule: the bottom and the top. The default of
// placed cells; walkable cells add their regions' vertical edges and wall traces instead of more
// levels (ViewCells::vertical_edges, wall_traces): on the quick start's city a middle level takes
// 12 sampled miss rays to 10 for 1.28 times the runs (docs/bake.md "Eye band").
constexpr int kPaperBandLevels = 2;
// The most band levels a bake takes (pvs bake --band-levels): a cell's runs grow with them.
constexpr int kMaxBandLevels = 16;

struct ViewCells {
  pvs::CellLayout layout;
  std::string description;
  // Empty, or one list per cell: the segments each cell's visibility is computed on instead of
  // the perimeters of its view region's rectangles (cell_visibility.h), for cells whose region
  // is not a box (BSP leaves: bsp_cells.h). Scene coordinates.
  std::vector<std::vector<Segment>> segments;
  // Cells without their own segments: the heights of the view region whose rectangles' perimeters
  // a cell's runs are (cell_rectangles): the bottom, the top and band_levels - 2 evenly spaced
  // between (>= 2). An eye between the two sees, along a near-horizontal ray, past the region's
  // side at its own height: the perimeters at the bottom and the top pass above and below that
  // point, and an edge between them catches most of what they miss (docs/bake.md "Eye band").
  int band_levels = kPaperBandLevels;
  // Cells without their own segments: also run the four vertical edges of the view region (the
  // box's corners from its bottom to its top), when it is not flat. An eye between two band
  // levels sees, along rays that leave through a side face between them, what no level's
  // perimeter passes through; the vertical edges pass through every height (on sauer_fdm6's
  // walkable cells they see 90% of the (cell, triangle) pairs that three levels miss).
  bool vertical_edges = false;
  // Empty, or one list per cell (cells without their own segments): the traces of the walls that
  // cross the middle of the cell's band (wall_traces.h), run as one more group after the
  // rectangles' perimeters. An eye next to a wall inside the cell sees past its edges what the
  // perimeter samples coarsely.
  std::vector<std::vector<Segment>> wall_traces;
  // Empty, or one value per cell: the largest near distance (scene units) at which the cell's
  // eyes see no surface cut by the near plane (a BSP leaf thinner than twice the clearance,
  // quake_bsp_volumes.h); the cell's runs use the smaller of it and the bake's near.
  std::vector<double> near_limit;
  // Empty, or one list per cell: faces of the cell's view region swept by chords inserted where
  // the visible set changes (face_sweep.h: adaptive_sweep at sweep_spacing), run after the cell's
  // segments, which then hold the region's edges (cell_visibility.h).
  std::vector<std::vector<FaceSweep>> sweeps;
  AdaptiveSpacing sweep_spacing;
  // Empty, or one list per cell (increasing ids): triangles the cell's eyes see without its runs,
  // united into its set (a BSP leaf's own boundary and contents when its runs sweep its portals:
  // bsp_cells.h), each with a witness ray from a point of the view region.
  struct OwnTriangle {
    uint32_t tri = 0;
    Vec3 eye, dir;  // scene coordinates; dir a unit vector
  };
  std::vector<std::vector<OwnTriangle>> own;
  // The cells' runs are shared between cells (a portal's, whose directions are split between its
  // two leaves): they keep the bake's near distance, and near_limit bounds the eyes' near only.
  bool shared_runs = false;
  // Empty, or one per cell: its view region (scene coordinates) when its runs lie outside it (a
  // portal's): a run's witness, an eye on the portal, is moved back along its ray into the
  // region, so that it is a ray from an eye of the cell (cell_witness_rays).
  std::vector<ConvexPolytope> regions;
  // Empty, or one list per cell whose runs lie on portals (bsp_cells.h): the portal (an index of
  // the bake's portal list, bsp_leaf_portals) that each of segments[c] lies on, and each of
  // sweeps[c]. A portal that has sweeps has no chords among its segments: they are its polygon's
  // edges, the base of each of its sweeps (cell_visibility.h).
  std::vector<std::vector<uint32_t>> segment_portal, sweep_portal;
  // Empty, or the cells' runs restricted to bounds of what they can see (bsp_bound.h): portal p's
  // bound is the leaves bound_leaves[p] (increasing map leaf numbers), leaf_triangles[l] the
  // triangles that touch leaf l. The runs of a segment or sweep composite the triangles of its
  // portal's bound only (cell_visibility.h), but for a segment whose run stands for several
  // portals' edges (Segment::run_planes), which composites the whole scene, and see what they see
  // without the restriction.
  std::vector<std::vector<uint32_t>> bound_leaves, leaf_triangles;
};

pvs::Box to_pvs_box(const Box3& b);
Box3 to_box3(const pvs::Box& b);

// Eye-height band [lo, hi] in scene units above a floor or a cell's bottom (lo <= hi).
struct EyeBand {
  double lo = 1.5, hi = 1.8;
};

// (a) A grid of nx * ny * nz cells over `box` (min <= max, finite; n* >= 1). With `eye`, a cell's
// view region spans its x and z range and [bottom + eye.lo, bottom + eye.hi] in y; without, the
// view region is the cell itself.
ViewCells grid_cells(const Box3& box, uint32_t nx, uint32_t ny, uint32_t nz,
                     const std::optional<EyeBand>& eye = std::nullopt);

// (a) The same with cells of (at most) `cell_size` per side: n = max(1, ceil(extent / cell_size))
// per axis. `cell_size` must be > 0.
ViewCells grid_cells_by_size(const Box3& box, double cell_size,
                             const std::optional<EyeBand>& eye = std::nullopt);

struct WalkableOptions {
  double cell_size = 2;           // side of a column in x and z (scene units), > 0
  EyeBand eye;                    // band above the floor
  double max_slope_degrees = 45;  // floor triangles: angle between the normal and +y below this
  // Front faces are wound clockwise (a Quake map's faces): floor and facing down are then taken
  // from -(b - a) x (c - a) (floor_triangle, walkable_reach.h).
  bool clockwise_front = false;
  // Drop a floor level that has no headroom: at every one of a 4 x 4 grid of sample points in the
  // column where the level's floor is, some other surface lies within eye.lo above it (the ground
  // under a building, the floor inside a wall). Point-sampled: errs towards keeping cells.
  bool require_headroom = true;
  // Only place cells in this box (x and z range of the columns, y range of the floors), if set.
  std::optional<Box3> clip;
  size_t state = 0;  // key state whose geometry is used
  // Reachability (walkable_reach.h): with starts, a level is kept only where `agent` can stand
  // on floor reachable from one of them; without, every level (with headroom) is kept.
  std::vector<WalkStart> starts;
  WalkAgent agent;
  // Starts whose point has no walkable floor under it: with `required_starts`, the first such
  // start throws PlacementError(StartWithoutFloor); otherwise it is left out (and recorded), and
  // only when no start has floor is PlacementError(StartWithoutFloor) thrown.
  bool required_starts = true;
};

// (b) Walkable cells. Columns start at the x/z minimum of `clip` (or of the scene bounds) and are
// cell_size wide (the last ones clipped to the clip box). In each column the floor pieces (the
// parts of floor triangles inside the column, clipped exactly, each of area above
// kMinFloorAreaFraction * cell_size^2) are grouped into levels: sorted by height, a piece joins
// the level below when its lowest point is within eye.hi of that level's highest point. A level
// [lo, hi] gives the cell [column x] x [lo + eye.lo, hi + eye.hi] x [column z]. With starts, a
// level is kept only when reachable_floor (voxel side min(cell_size / 4, agent.radius / 2 when
// > 0)) has a floor in a voxel column centred in the column at a height within
// [lo - t, hi + t], t = the voxel's side + its height (the voxels round floors up by at most
// their height, and a column's top is the highest floor over its side). Cell order: columns
// by z index, then x index, levels bottom to top. Deterministic (sequential, no threads).
// Triangles facing up are those with (b - a) x (c - a) having a positive y component (the
// opposite with clockwise_front): the winding matters (glTF's counter-clockwise front faces).
ViewCells walkable_cells(const Scene& scene, const WalkableOptions& options);

// How the cells of a bake are placed (pvs bake --box, --grid, --cell-size, --walkable,
// docs/bake.md): (a) a grid over `box`, given by its counts or by its cell size, or (b) walkable
// cells.
struct CellPlacement {
  std::optional<Box3> box;  // (a) the grid's box; (b) only place cells in it. Finite, min <= max
  std::optional<std::array<uint32_t, 3>> grid;  // (a) nx, ny, nz, each >= 1
  double cell_size = 0;   // (a) grid cells of (at most) this side; (b) column side; 0 = not given
  bool walkable = false;  // (b) instead of (a)
  std::optional<EyeBand> eye;     // band above a cell's bottom / a floor; (b) default EyeBand{}
  double max_slope_degrees = 45;  // (b) WalkableOptions::max_slope_degrees
  bool clockwise_front = false;   // (b) WalkableOptions::clockwise_front; the wall traces' front
  bool require_headroom = true;   // (b) WalkableOptions::require_headroom
  // (b) WalkableOptions::starts and required_starts; the agent's height (default: the eye band's
  // top), radius and step (default: a quarter of the band's top each), each finite, height > 0.
  std::vector<WalkStart> starts;
  bool required_starts = true;
  std::optional<double> agent_height, agent_radius, agent_step;
  // (a) and (b): ViewCells::band_levels (>= 2; not 2: recorded in the description); unset:
  // kPaperBandLevels.
  std::optional<int> band_levels;
  // (a) and (b): run the wall traces of each cell too (ViewCells::wall_traces), offset from their
  // walls by kWallTraceClearanceFactor times `near` (the bake's near distance, > 0), to the side
  // the winding faces (clockwise_front); recorded in the description ("wall_traces":
  // {"clearance": C, "front_faces": "clockwise" or "counter-clockwise"}). Unset: on for (b), off
  // for (a).
  std::optional<bool> wall_traces;
  double near = kDefaultNear;
  // (a) and (b): ViewCells::vertical_edges; recorded in the description ("vertical_edges": true).
  // Unset: on for (b), off for (a).
  std::optional<bool> vertical_edges;
};

// At most this many grid cells, or walkable columns, are placed (their index would not fit the
// memory of a bake long before the 2^32 cell ids of the format run out).
constexpr double kMaxPlacedCells = 1e7;

// Why place_view_cells refused a placement; nothing was placed.
enum class PlacementProblem {
  GridWithWalkable,   // grid counts given with walkable cells
  TooManyColumns,     // (b) more than kMaxPlacedCells columns over box (or the scene bounds)
  NoBox,              // (a) without a box
  GridAndCellSize,    // (a) both grid counts and a cell size
  TooManyGridCells,   // (a) nx * ny * nz > kMaxPlacedCells
  NoGridNorCellSize,  // (a) neither grid counts nor a cell size
  TooManySizedCells,  // (a) more than kMaxPlacedCells cells of cell_size over box
  BadAgent,           // (b) agent height <= 0, radius or step < 0, or one not finite
  StartWithoutFloor,  // (b) a start has no walkable floor under it (walkable_cells); or none has
};
class PlacementError : public std::invalid_argument {
 public:
  PlacementError(PlacementProblem problem, const std::string& what)
      : std::invalid_argument(what), problem_(problem) {}
  PlacementProblem problem() const { return problem_; }

 private:
  PlacementProblem problem_;
};

// The cells of `placement`: walkable_cells (cell_size 0 = 2) when `walkable`, else grid_cells
// (counts) or grid_cells_by_size (cell size). Throws PlacementError, checked in the order of
// PlacementProblem, before placing anything (StartWithoutFloor: while placing; its message names
// the start, its source and the agent). May return no cell (walkable: no floor in box).
// Deterministic; `scene` is read only for walkable cells and wall traces.
ViewCells place_view_cells(const Scene& scene, const CellPlacement& placement);

// The wall-trace options a bake's metadata records for its cells ("cells": {"wall_traces": {...}},
// CellPlacement::wall_traces); none when it records none (or an invalid clearance).
std::optional<WallTraceOptions> wall_traces_of(const std::string& metadata);

// The band levels a bake's metadata (JSON, pvs::FileInfo::metadata) records for its cells
// ("cells": {"band_levels": K}); kPaperBandLevels when it records none or an invalid one.
int band_levels_of(const std::string& metadata);

// Whether a bake's metadata records that its cells ran their view regions' vertical edges
// ("cells": {"vertical_edges": true}, ViewCells::vertical_edges).
bool vertical_edges_of(const std::string& metadata);

}  // namespace vislib
