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
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A conservative bound of what each cell can see, to which its runs are restricted
// (cell_visibility.h): cell c's runs see only triangles(c), candidates and occluders alike. Exact
// when no triangle left out is ever a first hit from the cell's view region: removing a surface
// that no ray from the region hits first changes no first hit (docs/quake.md). Stored as groups
// (a BSP leaf's faces), so that a bound of many cells over many triangles stays small.
struct CellBound {
  // One list per cell of group indices (into group_triangles); empty: no bound (every triangle).
  std::vector<std::vector<uint32_t>> cell_groups;
  std::vector<std::vector<uint32_t>> group_triangles;  // triangle ids of each group
  std::vector<uint32_t> always;                        // triangle ids kept for every cell
  bool empty() const { return cell_groups.empty(); }
  // The triangle ids of cell `cell` (< cell_groups.size()): the union of its groups' and
  // `always`, sorted, unique.
  std::vector<uint32_t> triangles(uint32_t cell) const;
};

// The cells of a bake and a JSON object (text) saying how they were placed, for the metadata of
// the PVS file.
struct ViewCells {
  pvs::CellLayout layout;
  std::string description;
  // Empty, or one list per cell: the segments each cell's visibility is computed on instead of
  // the perimeters of its view region's rectangles (cell_visibility.h), for cells whose region
  // is not a box (BSP leaves: bsp_cells.h). Scene coordinates.
  std::vector<std::vector<Segment>> segments;
  // Empty, or the triangles each cell's runs are restricted to (a static scene without spheres).
  CellBound bound;
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
  // Drop a floor level that has no headroom: at every one of a 4 x 4 grid of sample points in the
  // column where the level's floor is, some other surface lies within eye.lo above it (the ground
  // under a building, the floor inside a wall). Point-sampled: errs towards keeping cells.
  bool require_headroom = true;
  // Only place cells in this box (x and z range of the columns, y range of the floors), if set.
  std::optional<Box3> clip;
  size_t state = 0;  // key state whose geometry is used
};

// (b) Walkable cells. Columns start at the x/z minimum of `clip` (or of the scene bounds) and are
// cell_size wide (the last ones clipped to the clip box). In each column the floor pieces (the
// parts of floor triangles inside the column, clipped exactly, each of area above
// kMinFloorAreaFraction * cell_size^2) are grouped into levels: sorted by height, a piece joins
// the level below when its lowest point is within eye.hi of that level's highest point. A level
// [lo, hi] gives the cell [column x] x [lo + eye.lo, hi + eye.hi] x [column z]. Cell order: columns
// by z index, then x index, levels bottom to top. Deterministic (sequential, no threads).
// Triangles facing up are those with (b - a) x (c - a) having a positive y component: the
// winding matters (glTF's counter-clockwise front faces).
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
  bool require_headroom = true;   // (b) WalkableOptions::require_headroom
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
// PlacementProblem, before placing anything. May return no cell (walkable: no floor in box).
// Deterministic; `scene` is read only for walkable cells.
ViewCells place_view_cells(const Scene& scene, const CellPlacement& placement);

}  // namespace vislib
