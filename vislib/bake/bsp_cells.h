// bsp_cells.h: a Quake map's BSP leaves as view cells, in the form the PVS file stores them
// (pvs::CellLayout of kind BspTree, docs/pvs-format.md): the map's tree (model 0's nodes, the
// map's planes in scene coordinates), the leaf of each cell, the bounding box of each cell's volume
// (quake_bsp_volumes.h) and each cell's neighbours.
//
// Neighbours: two cells are neighbours when their leaves share a portal (bsp_portals.h: their
// volumes share a face of at least kBspPortalMinArea square units).
#pragma once

#include <cstdint>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/view_cells.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/import.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {

// The leaves of model 0 that become view cells: every leaf reached from model 0's head node whose
// contents are empty or a liquid (water, slime, lava), in increasing leaf number. Solid and sky
// leaves are not cells.
std::vector<uint32_t> bsp_cell_leaves(const QuakeBsp& bsp);

// The BSP-tree layout of `bsp` with cell c the leaf cell_leaves[c] (each reached from model 0's
// head node, increasing, no solid leaf). Planes: all of the map's, in map order, as
// quake_to_scene(normal) and the same dist, so a point's side is its Quake side (up to the order
// of the dot product's sums). Nodes: model 0's, renumbered in depth-first order (front child
// first), so models 1+ are left out. Leaf numbers are the map's (leaf_cell has one entry per map
// leaf). Boxes: the scene-space bounding box of the leaf's volume (bsp_leaf_pieces). Neighbours as
// the file comment says. Deterministic. Throws std::invalid_argument on a bad cell_leaves.
pvs::CellLayout bsp_leaf_layout(const QuakeBsp& bsp, const std::vector<uint32_t>& cell_leaves);

// The default spacing of the segments that sweep each boundary face of a leaf's view region
// (Quake units, about 40 cm): what a point inside a leaf sees is seen from the region's boundary
// (the region holds no geometry), and the face is sampled by parallel segments at most this far
// apart (docs/quake.md measures what the spacing buys).
constexpr double kBspFaceSpacing = 16.0;

// The segments a convex region's visibility is computed on (Quake coordinates in, scene
// coordinates out, quake_to_scene): first every edge of every face of `region`, in face order and
// each once (an edge shared by two faces is kept where it first appears); then, when `spacing` >
// 0, for each face in order, the chords of the face parallel to its longest edge (the first such
// edge in vertex order) at equal steps of at most `spacing` Quake units across it, strictly
// between its extreme vertices. spacing 0: the edges only. Degenerate edges and faces (shorter or
// narrower than 1e-6 units) give no segment. Deterministic.
std::vector<Segment> bsp_region_segments(const ConvexPolytope& region, double spacing);

// What a leaf's runs are restricted to (ViewCells::bound; docs/quake.md, "Restricting a leaf's
// runs"): nothing (every triangle); our own portal flow (bsp_portal_base_vis over the portals of
// every cell leaf, bsp_portals.h); or the map's own visibility row (bsp_leaf_sees, the leaf itself
// added), only as conservative as the compiler's vis.
enum class BspBound { none, portal, map_vis };
// "none", "portal", "map-vis".
const char* bsp_bound_name(BspBound bound);

// The leaves (map leaf numbers, sorted) that each of `leaves` (an increasing subset of
// bsp_cell_leaves) may see under `bound`, in the order of `leaves`; BspBound::none: every leaf
// reached from model 0's head node. Deterministic.
std::vector<std::vector<uint32_t>> bsp_bound_leaves(const QuakeBsp& bsp, BspBound bound,
                                                    const std::vector<uint32_t>& leaves);

// The triangle bound of cells whose leaves are `leaves` under `bound` (empty for BspBound::none):
// cell c keeps the triangles (ids of the scene imported with `scene`, bsp_face_triangles) of the
// faces in the marksurfaces of bsp_bound_leaves(bsp, bound, leaves)[c], and every triangle of a
// face in no cell leaf's marksurfaces (other models, faces marked only in sky leaves), which no
// bound drops. Deterministic.
CellBound bsp_cell_bound(const QuakeBsp& bsp, BspBound bound, const std::vector<uint32_t>& leaves,
                         const LoadOptions& scene);

struct BspCellOptions {
  double face_spacing = kBspFaceSpacing;  // bsp_region_segments' spacing, >= 0 (0: edges only)
  // The leaves to bake, a subset of bsp_cell_leaves (increasing); empty: all of them.
  std::vector<uint32_t> leaves;
  // The import options the scene was loaded with (bsp_models, bsp_liquids), recorded in the
  // description so that a reader knows what the triangle ids index.
  LoadOptions scene;
  BspBound bound = BspBound::none;  // the cells' bound (bsp_cell_bound)
};

// The view cells of a map's BSP leaves: layout bsp_leaf_layout(bsp, leaves), cell c's segments
// bsp_region_segments(bsp_leaf_view_region(volume of its leaf), face_spacing), and a description
// (JSON) recording the cells' kind ("bsp-leaves"), the spacing, the inset rule (kBspLeafInset,
// kBspLeafMinInset, the count of leaves inset less than kBspLeafInset), the scene options and the
// bound (`bound`: bsp_bound_name; the cells' bound is bsp_cell_bound).
// Throws std::invalid_argument for leaves that are not an increasing subset of bsp_cell_leaves.
// Deterministic.
ViewCells bsp_leaf_cells(const QuakeBsp& bsp, const BspCellOptions& options);

}  // namespace vislib
