// bsp_cells.cpp: a Quake map's BSP leaves as view cells (bsp_cells.h).
#include "vislib/bake/bsp_cells.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {

namespace {

// Two faces of BSP leaf volumes (Quake units) lie on one plane, facing each other, when their
// unit normals are opposite to within this (1 + dot of the normals) and each vertex of one is
// within kBspFaceCoplanarDistance of the other's plane (vislib/bake/bsp_cells.h). The volumes
// come from the same float planes, so a shared face agrees to about 1e-12 units.
constexpr double kBspFaceOppositeNormals = 1e-9;
constexpr double kBspFaceCoplanarDistance = 1e-6;
// Two leaf volumes are neighbours when their shared face has at least this area (square Quake
// units; a real portal is at least about 1).
constexpr double kBspPortalMinArea = 1e-3;

// A face of a leaf volume with its plane: unit outward normal and offset (dot(n, p) = offset).
struct PlanarFace {
  const std::vector<Vec3>* poly;
  Vec3 normal;
  double offset;
};

PlanarFace planar(const std::vector<Vec3>& poly) {
  Vec3 n{0, 0, 0};  // Newell's normal: exact direction for a planar polygon
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  n = n * (1.0 / length(n));
  return {&poly, n, dot(n, poly[0])};
}

using P2 = std::array<double, 2>;

double signed_area(const std::vector<P2>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const P2& u = p[i];
    const P2& v = p[(i + 1) % p.size()];
    a += u[0] * v[1] - v[0] * u[1];
  }
  return 0.5 * a;
}

// Area of the intersection of two convex polygons, both counter-clockwise (Sutherland-Hodgman).
double overlap_area(std::vector<P2> a, const std::vector<P2>& b) {
  for (size_t i = 0; i < b.size() && a.size() >= 3; ++i) {
    const P2& p = b[i];
    const P2& q = b[(i + 1) % b.size()];
    auto side = [&](const P2& x) {
      return (q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0]);
    };
    std::vector<P2> out;
    for (size_t k = 0; k < a.size(); ++k) {
      const P2& u = a[k];
      const P2& v = a[(k + 1) % a.size()];
      double su = side(u), sv = side(v);
      if (su >= 0) out.push_back(u);
      if ((su >= 0) != (sv >= 0)) {
        double t = su / (su - sv);
        out.push_back({u[0] + (v[0] - u[0]) * t, u[1] + (v[1] - u[1]) * t});
      }
    }
    a = std::move(out);
  }
  return a.size() >= 3 ? signed_area(a) : 0.0;
}

// The polygon projected on the two axes other than `drop`, counter-clockwise.
std::vector<P2> project(const std::vector<Vec3>& poly, int drop) {
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  std::vector<P2> out;
  for (const Vec3& p : poly) out.push_back({p[u], p[v]});
  if (signed_area(out) < 0) std::reverse(out.begin(), out.end());
  return out;
}

// True if a face of `a` and a face of `b` lie on one plane facing each other and overlap with
// positive area (kBspPortalMinArea).
bool share_face(const std::vector<PlanarFace>& a, const std::vector<PlanarFace>& b) {
  for (const PlanarFace& fa : a)
    for (const PlanarFace& fb : b) {
      if (1.0 + dot(fa.normal, fb.normal) > kBspFaceOppositeNormals) continue;
      bool coplanar = true;
      for (const Vec3& v : *fb.poly)
        coplanar = coplanar && std::fabs(dot(fa.normal, v) - fa.offset) <= kBspFaceCoplanarDistance;
      if (!coplanar) continue;
      int drop = 0;
      for (int k = 1; k < 3; ++k)
        if (std::fabs(fa.normal[k]) > std::fabs(fa.normal[drop])) drop = k;
      // The projected area shrinks by |n[drop]| (at least 1/sqrt(3)); undo that.
      double area = overlap_area(project(*fa.poly, drop), project(*fb.poly, drop)) /
                    std::fabs(fa.normal[drop]);
      if (area >= kBspPortalMinArea) return true;
    }
  return false;
}

// Segment end points closer than this (Quake units) are one point: an edge of two faces of one
// polytope is computed once per face and agrees to about 1e-12 units; shorter segments are dropped.
constexpr double kBspSameEndpoint = kSweepMinChord;

bool same_segment(const Segment& s, Vec3 a, Vec3 b) {
  auto near = [](Vec3 p, Vec3 q) { return length(p - q) <= kBspSameEndpoint; };
  return (near(s.from, a) && near(s.to, b)) || (near(s.from, b) && near(s.to, a));
}

// The sweep of each face of `region` (face_sweep_of), in face order (Quake coordinates).
std::vector<FaceSweep> region_sweeps(const ConvexPolytope& region) {
  std::vector<FaceSweep> out;
  for (const std::vector<Vec3>& f : region.faces) {
    if (f.size() < 3) continue;
    const PlanarFace pf = planar(f);
    if (!std::isfinite(pf.normal.x)) continue;
    if (auto s = face_sweep_of(f, pf.normal, kBspSameEndpoint)) out.push_back(std::move(*s));
  }
  return out;
}

// `s` in scene coordinates (quake_to_scene is a rotation: positions along and across keep).
FaceSweep scene_sweep(FaceSweep s) {
  for (Vec3& v : s.face) v = quake_to_scene(v);
  s.along = quake_to_scene(s.along);
  s.across = quake_to_scene(s.across);
  return s;
}

bool boxes_touch(const Box3& a, const Box3& b) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] > b.max[k] + kBspFaceCoplanarDistance ||
        b.min[k] > a.max[k] + kBspFaceCoplanarDistance)
      return false;
  return true;
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
  std::vector<std::vector<PlanarFace>> faces(C);
  std::vector<Box3> bounds(C);
  for (const BspLeafPiece& piece : pieces) {
    uint32_t c = L.leaf_cell[piece.leaf];
    if (c == pvs::kNoCell || piece.volume.empty()) continue;
    for (const auto& f : piece.volume.faces) faces[c].push_back(planar(f));
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
  for (size_t a = 0; a < C; ++a)
    for (size_t b = a + 1; b < C; ++b)
      if (boxes_touch(bounds[a], bounds[b]) && share_face(faces[a], faces[b])) {
        L.neighbours[a].push_back(uint32_t(b));
        L.neighbours[b].push_back(uint32_t(a));
      }
  return L;  // neighbours sorted: a's list gets b in increasing order, and earlier a's first
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
    for (const FaceSweep& sweep : region_sweeps(region)) {
      const std::vector<Segment> c = even_chords(sweep, spacing, kBspSameEndpoint);
      quake.insert(quake.end(), c.begin(), c.end());
    }
  std::vector<Segment> out;
  out.reserve(quake.size());
  for (const Segment& s : quake) out.push_back({quake_to_scene(s.from), quake_to_scene(s.to)});
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
  uint32_t thin = 0, uninset = 0, clipped = 0;
  std::vector<double> near_limit(leaves.size(), std::numeric_limits<double>::infinity());
  for (const BspLeafPiece& piece : bsp_leaf_pieces(bsp)) {
    const uint32_t c = cells.layout.leaf_cell[piece.leaf];
    if (c == pvs::kNoCell || piece.volume.empty()) continue;
    const BspViewRegion region = bsp_leaf_view_region(piece.volume, options.near);
    if (region.inset < kBspLeafInset) ++thin;
    if (region.inset == 0) ++uninset;
    if (region.near_limit < options.near) {
      ++clipped;
      near_limit[c] = std::min(near_limit[c], region.near_limit);
    }
    std::vector<Segment> s =
        bsp_region_segments(region.volume, options.adaptive ? 0.0 : options.face_spacing);
    cells.segments[c].insert(cells.segments[c].end(), s.begin(), s.end());
    if (options.adaptive) {
      cells.sweeps.resize(leaves.size());
      for (const FaceSweep& f : region_sweeps(region.volume))
        cells.sweeps[c].push_back(scene_sweep(f));
    }
  }
  if (options.adaptive) cells.sweep_spacing = *options.adaptive;
  if (clipped > 0) cells.near_limit = std::move(near_limit);
  const char* liquids = options.scene.bsp_liquids == BspLiquids::omit          ? "omit"
                        : options.scene.bsp_liquids == BspLiquids::see_through ? "see-through"
                                                                               : "opaque";
  nlohmann::json d = {
      {"kind", "bsp-leaves"},
      {"leaves", leaves.size()},
      {"leaf_subset", !options.leaves.empty()},
      {"face_spacing", options.face_spacing},
      {"face_sweep", options.adaptive ? "adaptive" : "even"},
      {"face_spacing_units", "quake"},
      {"region",
       "leaf volume inset by inset units (halved down to the larger of min_inset and "
       "clearance for thin leaves, then clearance; a leaf thinner than twice the clearance by "
       "half its largest inset, its near distance clipped to that over clearance_factor); its "
       "edges and chords of each face parallel to its longest edge at most face_spacing apart"},
      {"inset", kBspLeafInset},
      {"min_inset", kBspLeafMinInset},
      {"clearance_factor", kNearClearanceFactor},
      {"clearance", kNearClearanceFactor * options.near},
      {"leaves_inset_less", thin},
      {"leaves_not_inset", uninset},
      {"leaves_near_clipped", clipped},
      {"bsp_models", options.scene.bsp_models == BspModels::all ? "all" : "world"},
      {"bsp_liquids", liquids}};
  if (options.adaptive) {
    d["chord_coarse"] = options.adaptive->coarse;
    d["chord_floor"] = options.adaptive->floor;
  }
  cells.description = d.dump();
  return cells;
}

}  // namespace vislib
