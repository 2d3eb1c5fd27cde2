// bsp_cells.h: a Quake map's BSP leaves as view cells, in the form the PVS file stores them
// (pvs::CellLayout of kind BspTree, docs/pvs-format.md): the map's tree (model 0's nodes, the
// map's planes in scene coordinates), the leaf of each cell, the bounding box of each cell's volume
// (quake_bsp_volumes.h) and each cell's neighbours.
//
// Neighbours: the map file holds no portals (the compiler keeps them in a separate .prt file), so
// two cells are neighbours when their leaves' volumes share a face of positive area: a face of
// one and a face of the other on one plane with opposite normals whose overlap has at least
// kBspPortalMinArea square units (tolerances named in bsp_cells.cpp). That is the portal the
// compiler would put between them: a portal is the part of a node's plane where two leaves meet.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/bsp_bound.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/tolerances.h"
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
// The default spacing of the chords across a portal (BspSweep::Portals, Quake units): a portal is
// swept once, where a face sweep samples it from both leaves' faces and through their walls'
// chords, so its chords lie twice as close; on lqdm1 the sampled misses then match the face
// sweep's at 16 for half its CPU (docs/quake.md "Portals").
constexpr double kBspPortalSpacing = 8.0;
// The default chords of a portal sweep (BspSweep::Portals, Quake units; `pvs bake` sweeps portals
// adaptively unless told --face-sweep even): the first chords at most 256 apart, inserted down to
// 4, each portal cut into strips at most 256 long along its chords, a chord inserted below a
// probe that saw ids new to its family computing only the cube tiles toward them, on every cube
// face where they can appear, and a second family of chords perpendicular to the first, inserted
// down to 16.
// Against the whole cube down to 8 the tiles cost less CPU on lqdm1 whole and about as much on
// leaf samples of e1m2 and e2m3, for fewer sampled misses on all three: the floor of 4 buys the
// misses back that the tiles give up, and the tiles pay for the floor (docs/quake.md "Chords that
// look toward what made them"). The crossed family finds views through patches of a portal thin
// across the first family's chords, which no finer floor does: a third to a quarter of the
// sampled misses on the three maps for 1.3-1.4 times the CPU. With it the tiles on every face
// miss as often as on one face, for 0.65-0.86 of the CPU (docs/quake.md "Crossed chords"). The
// crossed chords stop at 16: the patches they are there for are long across them; against 4 that
// costs 0.75 of e1m2's leaf sample's CPU, for the same sampled misses on lqdm1 and one or two
// more rays in 100 million on the big maps' samples. A probe's ids count as new only when its
// family has not seen them (AdaptiveSpacing::new_to_family), and the first chords lie 256 apart
// where 128 had cost whole cubes that the masked chords inserted below them now replace: together
// 0.6-0.8 of the CPU of the three maps' samples for one or two more sampled miss rays in 100
// million (docs/quake.md "Chords new to their family").
constexpr AdaptiveSpacing kBspPortalChords{256.0,          4.0,  256.0, ChordTiles::NewEveryFace,
                                           kChordTileSize, true, 16.0,  true};

// The segments a convex region's visibility is computed on (Quake coordinates in, scene
// coordinates out, quake_to_scene): first every edge of every face of `region`, in face order and
// each once (an edge shared by two faces is kept where it first appears); then, when `spacing` >
// 0, for each face in order, the chords of the face parallel to its longest edge (the first such
// edge in vertex order) at equal steps of at most `spacing` Quake units across it, strictly
// between its extreme vertices. spacing 0: the edges only. Degenerate edges and faces (shorter or
// narrower than 1e-6 units) give no segment. Deterministic.
std::vector<Segment> bsp_region_segments(const ConvexPolytope& region, double spacing);

// What a leaf's runs sweep (docs/quake.md "Portals"):
//  Portals: the portals between leaves (bsp_portals.h), each swept once for its two leaves, a run's
//    directions split by the portal's plane (Segment::side_normal): each leaf takes the directions
//    that leave it; plus the triangles on or in the leaf's volume (ViewCells::own). The runs keep
//    the bake's near distance, so that the two leaves share them (near_limit bounds the eyes'
//    near only).
//  Faces: every face of the leaf's view region, walls included, in every direction.
enum class BspSweep { Portals, Faces };

struct BspCellOptions {
  // The spacing of the chords across each swept polygon (a portal, or a face of the view region),
  // >= 0 (0: its edges only).
  double face_spacing = kBspFaceSpacing;
  // The leaves to bake, a subset of bsp_cell_leaves (increasing); empty: all of them.
  std::vector<uint32_t> leaves;
  // The import options the scene was loaded with (bsp_models, bsp_liquids), recorded in the
  // description so that a reader knows what the triangle ids index.
  LoadOptions scene;
  // Set: each face of a leaf's region is swept adaptively (face_sweep.h: coarse chords, one
  // inserted between two neighbours while it sees ids neither sees, down to the floor spacing;
  // Quake units), and face_spacing is not used; the cell's segments are the region's edges.
  std::optional<AdaptiveSpacing> adaptive = std::nullopt;
  // The bake's near distance (Quake units, > 0): each view region keeps its eyes clear of the
  // leaf's surfaces by kNearClearanceFactor times it (bsp_leaf_view_region).
  double near = kDefaultNear;
  BspSweep sweep = BspSweep::Faces;
  // The bound each portal's runs are restricted to (bsp_bound.h; BspSweep::Portals only): exact
  // with Portals, trusting the map's vis with MapVis.
  BspBound bound = BspBound::None;
  // BspSweep::Portals: the edges of open portals that meet along one line share one run, split by
  // each portal's plane (share_portal_edges in bsp_cells.cpp; Segment::run_planes). Cheaper, but
  // the run's eyes lie up to a few clearances beyond a wall that ends where the portals meet, and
  // a portal's leaves then take ids seen past it (docs/quake.md "Edges shared where portals
  // meet"). False: each edge is its own run, on its own portal.
  bool share_edges = false;
};

// The view cells of a map's BSP leaves: layout bsp_leaf_layout(bsp, leaves), cell c's segments
// (BspSweep::Faces) bsp_region_segments(bsp_leaf_view_region(volume of its leaf, near),
// face_spacing), or (BspSweep::Portals) for each portal of its leaf in bsp_leaf_portals order
// (among all of bsp_cell_leaves, whichever are baked) the polygon's edges and, with face_spacing >
// 0 and no adaptive sweep, its even chords (face_sweep.h), all in scene coordinates with the
// portal's normal and the leaf's side, an open portal's edges sharing their runs with the other
// portals' that meet them along a line when options.share_edges says so (Segment::run_planes,
// with no bound); with an adaptive sweep, the portal's FaceSweep; and
// ViewCells::own from bsp_volume_triangles of its volume, each with a witness eye at the vertex
// mean of the view region; the portal each segment and sweep lies on (ViewCells::segment_portal,
// sweep_portal); with options.bound, each portal's bound (ViewCells::bound_leaves;
// std::invalid_argument with BspSweep::Faces). Portals need `scene`, the
// map as loaded with options.scene (std::invalid_argument without it). The cells'
// near_limit (only when some leaf's region clips the near distance), and a description (JSON)
// recording the cells' kind ("bsp-leaves"), the spacing, the inset rule (kBspLeafInset,
// kBspLeafMinInset, the clearance, the counts of leaves inset less than kBspLeafInset, not inset
// and with a clipped near distance), whether portal edges share runs ("portal_edges") and the
// scene options.
// Throws std::invalid_argument for leaves that are not an increasing subset of bsp_cell_leaves.
// Deterministic.
ViewCells bsp_leaf_cells(const QuakeBsp& bsp, const BspCellOptions& options,
                         const Scene* scene = nullptr);

}  // namespace vislib
