// bsp_cells.cpp: a Quake map's BSP leaves as view cells (bsp_cells.h).
#include "vislib/bake/bsp_cells.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "vislib/bake/bsp_portals.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {

namespace {

// Segment end points closer than this (Quake units) are one point: an edge of two faces of one
// polytope is computed once per face and agrees to about 1e-12 units; shorter segments are dropped.
constexpr double kBspSameEndpoint = 1e-6;

bool same_segment(const Segment& s, Vec3 a, Vec3 b) {
  auto near = [](Vec3 p, Vec3 q) { return length(p - q) <= kBspSameEndpoint; };
  return (near(s.from, a) && near(s.to, b)) || (near(s.from, b) && near(s.to, a));
}

// The chords of convex polygon `poly` (normal `n`) parallel to its longest edge, at equal steps of
// at most `spacing` across it, strictly between its extreme vertices.
void face_chords(const std::vector<Vec3>& poly, Vec3 n, double spacing, std::vector<Segment>& out) {
  const size_t m = poly.size();
  size_t longest = 0;
  for (size_t i = 1; i < m; ++i)
    if (length(poly[(i + 1) % m] - poly[i]) > length(poly[(longest + 1) % m] - poly[longest]))
      longest = i;
  Vec3 d = poly[(longest + 1) % m] - poly[longest];
  if (length(d) <= kBspSameEndpoint) return;
  d = d * (1.0 / length(d));
  Vec3 w = cross(n, d);
  w = w * (1.0 / length(w));
  double lo = dot(w, poly[0]), hi = lo;
  for (const Vec3& p : poly) {
    lo = std::min(lo, dot(w, p));
    hi = std::max(hi, dot(w, p));
  }
  const double width = hi - lo;
  if (!(width > spacing)) return;
  const int steps = int(std::ceil(width / spacing));
  for (int k = 1; k < steps; ++k) {
    const double h = lo + width * double(k) / double(steps);
    bool any = false;
    Vec3 a{}, b{};
    double ta = 0, tb = 0;
    for (size_t i = 0; i < m; ++i) {
      const Vec3& u = poly[i];
      const Vec3& v = poly[(i + 1) % m];
      const double hu = dot(w, u), hv = dot(w, v);
      if (hu == hv || h < std::min(hu, hv) || h > std::max(hu, hv)) continue;
      const Vec3 p = u + (v - u) * ((h - hu) / (hv - hu));
      const double t = dot(d, p);
      if (!any || t < ta) {
        a = p;
        ta = t;
      }
      if (!any || t > tb) {
        b = p;
        tb = t;
      }
      any = true;
    }
    if (any && length(b - a) > kBspSameEndpoint) out.push_back({a, b});
  }
}

}  // namespace

std::vector<uint32_t> bsp_cell_leaves(const QuakeBsp& bsp) {
  std::vector<uint8_t> reached(bsp.leaves.size(), 0);
  std::vector<int32_t> stack = {bsp.models[0].headnode[0]};
  while (!stack.empty()) {
    int32_t ref = stack.back();
    stack.pop_back();
    if (ref < 0) {
      reached[size_t(-(int64_t(ref) + 1))] = 1;
      continue;
    }
    for (int32_t child : bsp.nodes[size_t(ref)].children) stack.push_back(child);
  }
  std::vector<uint32_t> out;
  for (uint32_t l = 0; l < bsp.leaves.size(); ++l) {
    int32_t c = bsp.leaves[l].contents;
    if (reached[l] && (c == kBspContentsEmpty || bsp_contents_liquid(c))) out.push_back(l);
  }
  return out;
}

pvs::CellLayout bsp_leaf_layout(const QuakeBsp& bsp, const std::vector<uint32_t>& cell_leaves) {
  pvs::CellLayout L;
  L.kind = pvs::LayoutKind::BspTree;
  for (const BspPlane& p : bsp.planes) {
    Vec3 n = quake_to_scene({p.normal[0], p.normal[1], p.normal[2]});
    L.planes.push_back({{n.x, n.y, n.z}, double(p.dist)});
  }
  // Model 0's nodes in depth-first order, front child first: new index per map node.
  std::vector<int32_t> renumber(bsp.nodes.size(), -1);
  std::vector<int32_t> order;
  {
    std::vector<int32_t> stack = {bsp.models[0].headnode[0]};
    while (!stack.empty()) {
      int32_t ref = stack.back();
      stack.pop_back();
      if (ref < 0) continue;
      renumber[size_t(ref)] = int32_t(order.size());
      order.push_back(ref);
      const BspNode& n = bsp.nodes[size_t(ref)];
      stack.push_back(n.children[1]);
      stack.push_back(n.children[0]);
    }
  }
  auto map_ref = [&](int32_t ref) { return ref < 0 ? ref : renumber[size_t(ref)]; };
  for (int32_t m : order) {
    const BspNode& n = bsp.nodes[size_t(m)];
    pvs::BspNode out;
    out.plane = n.plane;
    out.children[0] = map_ref(n.children[0]);
    out.children[1] = map_ref(n.children[1]);
    L.nodes.push_back(out);
  }
  L.root = map_ref(bsp.models[0].headnode[0]);

  L.leaf_cell.assign(bsp.leaves.size(), pvs::kNoCell);
  for (uint32_t c = 0; c < cell_leaves.size(); ++c) {
    uint32_t l = cell_leaves[c];
    if (l == 0 || l >= bsp.leaves.size() || (c > 0 && l <= cell_leaves[c - 1]))
      throw std::invalid_argument(
          "bsp_leaf_layout: cell leaves must be increasing, non-solid "
          "leaves of the map (leaf " +
          std::to_string(l) + ")");
    L.leaf_cell[l] = c;
  }
  L.cell_leaf = cell_leaves;

  // Each cell's volume: its leaf's pieces (one for a leaf reached once).
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(bsp);
  const size_t C = cell_leaves.size();
  std::vector<Box3> bounds(C);
  for (const BspLeafPiece& piece : pieces) {
    uint32_t c = L.leaf_cell[piece.leaf];
    if (c == pvs::kNoCell || piece.volume.empty()) continue;
    Box3 b = piece.volume.bounds();
    bounds[c].extend(b.min);
    bounds[c].extend(b.max);
  }
  L.boxes.resize(C);
  for (size_t c = 0; c < C; ++c) {
    if (bounds[c].empty())
      throw std::invalid_argument("bsp_leaf_layout: leaf " + std::to_string(cell_leaves[c]) +
                                  " has no volume");
    // Scene (x, y, z) = Quake (x, z, -y).
    const Box3& q = bounds[c];
    L.boxes[c] = {{q.min.x, q.min.z, -q.max.y}, {q.max.x, q.max.z, -q.min.y}};
  }
  L.neighbours.assign(C, {});
  for (const BspPortal& p : bsp_leaf_portals(pieces, cell_leaves)) {
    const uint32_t a = L.leaf_cell[p.leaves[0]], b = L.leaf_cell[p.leaves[1]];
    L.neighbours[a].push_back(b);
    L.neighbours[b].push_back(a);
  }
  return L;  // neighbours sorted: portals come by (lower, higher) leaf, and leaves increase
}

std::vector<Segment> bsp_region_segments(const ConvexPolytope& region, double spacing) {
  assert(spacing >= 0);
  std::vector<Segment> quake;
  for (const std::vector<Vec3>& f : region.faces)
    for (size_t i = 0; i < f.size(); ++i) {
      const Vec3 a = f[i], b = f[(i + 1) % f.size()];
      if (length(b - a) <= kBspSameEndpoint) continue;
      bool seen = false;
      for (const Segment& s : quake) seen = seen || same_segment(s, a, b);
      if (!seen) quake.push_back({a, b});
    }
  if (spacing > 0)
    for (const std::vector<Vec3>& f : region.faces) {
      if (f.size() < 3) continue;
      const Vec3 n = polygon_normal(f);
      if (!std::isfinite(n.x)) continue;
      face_chords(f, n, spacing, quake);
    }
  std::vector<Segment> out;
  out.reserve(quake.size());
  for (const Segment& s : quake) out.push_back({quake_to_scene(s.from), quake_to_scene(s.to)});
  return out;
}

const char* bsp_bound_name(BspBound bound) {
  return bound == BspBound::portal ? "portal" : bound == BspBound::map_vis ? "map-vis" : "none";
}

std::vector<std::vector<uint32_t>> bsp_bound_leaves(const QuakeBsp& bsp, BspBound bound,
                                                    const std::vector<uint32_t>& leaves) {
  std::vector<std::vector<uint32_t>> out;
  if (bound == BspBound::map_vis) {
    for (uint32_t l : leaves) {
      std::vector<uint32_t> sees = bsp_leaf_sees(bsp, l);
      if (!std::binary_search(sees.begin(), sees.end(), l))
        sees.insert(std::upper_bound(sees.begin(), sees.end(), l), l);
      out.push_back(std::move(sees));
    }
    return out;
  }
  const std::vector<uint32_t> all = bsp_cell_leaves(bsp);
  if (bound == BspBound::none) {
    std::vector<uint32_t> reached;
    for (const BspLeafPiece& p : bsp_leaf_pieces(bsp)) reached.push_back(p.leaf);
    std::sort(reached.begin(), reached.end());
    reached.erase(std::unique(reached.begin(), reached.end()), reached.end());
    return std::vector<std::vector<uint32_t>>(leaves.size(), reached);
  }
  const std::vector<std::vector<uint32_t>> flow =
      bsp_portal_base_vis(bsp_leaf_portals(bsp_leaf_pieces(bsp), all), all);
  for (uint32_t l : leaves)
    out.push_back(flow[size_t(std::lower_bound(all.begin(), all.end(), l) - all.begin())]);
  return out;
}

CellBound bsp_cell_bound(const QuakeBsp& bsp, BspBound bound, const std::vector<uint32_t>& leaves,
                         const LoadOptions& scene) {
  CellBound out;
  if (bound == BspBound::none) return out;
  const std::vector<BspFaceTriangles> faces = bsp_face_triangles(bsp, scene);
  auto triangles_of = [&](uint32_t f, std::vector<uint32_t>& ids) {
    for (uint32_t k = 0; k < faces[f].triangle_count; ++k)
      ids.push_back(faces[f].first_triangle + k);
  };
  // A group per map leaf: the triangles of its marksurfaces.
  out.group_triangles.resize(bsp.leaves.size());
  std::vector<uint8_t> marked(faces.size(), 0);
  for (uint32_t l = 0; l < bsp.leaves.size(); ++l) {
    const BspLeaf& leaf = bsp.leaves[l];
    for (uint32_t k = 0; k < leaf.marksurface_count; ++k)
      triangles_of(bsp.marksurfaces[leaf.first_marksurface + k], out.group_triangles[l]);
  }
  for (uint32_t l : bsp_cell_leaves(bsp)) {
    const BspLeaf& leaf = bsp.leaves[l];
    for (uint32_t k = 0; k < leaf.marksurface_count; ++k)
      marked[bsp.marksurfaces[leaf.first_marksurface + k]] = 1;
  }
  for (uint32_t f = 0; f < faces.size(); ++f)
    if (!marked[f]) triangles_of(f, out.always);
  out.cell_groups = bsp_bound_leaves(bsp, bound, leaves);
  return out;
}

ViewCells bsp_leaf_cells(const QuakeBsp& bsp, const BspCellOptions& options) {
  assert(options.face_spacing >= 0);
  const std::vector<uint32_t> all = bsp_cell_leaves(bsp);
  std::vector<uint32_t> leaves = options.leaves.empty() ? all : options.leaves;
  for (size_t i = 0; i < leaves.size(); ++i)
    if (!std::binary_search(all.begin(), all.end(), leaves[i]) ||
        (i > 0 && leaves[i] <= leaves[i - 1]))
      throw std::invalid_argument("leaf " + std::to_string(leaves[i]) +
                                  " is not an empty or liquid leaf of model 0 in increasing order");
  ViewCells cells;
  cells.layout = bsp_leaf_layout(bsp, leaves);
  cells.segments.resize(leaves.size());
  uint32_t thin = 0, uninset = 0;
  for (const BspLeafPiece& piece : bsp_leaf_pieces(bsp)) {
    const uint32_t c = cells.layout.leaf_cell[piece.leaf];
    if (c == pvs::kNoCell || piece.volume.empty()) continue;
    const BspViewRegion region = bsp_leaf_view_region(piece.volume);
    if (region.inset < kBspLeafInset) ++thin;
    if (region.inset == 0) ++uninset;
    std::vector<Segment> s = bsp_region_segments(region.volume, options.face_spacing);
    cells.segments[c].insert(cells.segments[c].end(), s.begin(), s.end());
  }
  const char* liquids = options.scene.bsp_liquids == BspLiquids::omit          ? "omit"
                        : options.scene.bsp_liquids == BspLiquids::see_through ? "see-through"
                                                                               : "opaque";
  nlohmann::json d = {
      {"kind", "bsp-leaves"},
      {"leaves", leaves.size()},
      {"leaf_subset", !options.leaves.empty()},
      {"face_spacing", options.face_spacing},
      {"face_spacing_units", "quake"},
      {"region",
       "leaf volume inset by inset units (halved down to min_inset for thin leaves, else 0); "
       "its edges and chords of each face parallel to its longest edge at most face_spacing "
       "apart"},
      {"inset", kBspLeafInset},
      {"min_inset", kBspLeafMinInset},
      {"leaves_inset_less", thin},
      {"leaves_not_inset", uninset},
      {"bsp_models", options.scene.bsp_models == BspModels::all ? "all" : "world"},
      {"bsp_liquids", liquids},
      {"bound", bsp_bound_name(options.bound)}};
  cells.description = d.dump();
  cells.bound = bsp_cell_bound(bsp, options.bound, leaves, options.scene);
  return cells;
}

}  // namespace vislib
