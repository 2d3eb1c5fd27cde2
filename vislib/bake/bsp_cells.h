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
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/scene/quake_bsp.h"

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

}  // namespace vislib
