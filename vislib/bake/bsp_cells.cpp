// bsp_cells.cpp: a Quake map's BSP leaves as view cells (bsp_cells.h).
#include "vislib/bake/bsp_cells.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "vislib/bake/bsp_portals.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {

namespace {

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
    const Vec3 n = polygon_normal(f);
    if (!std::isfinite(n.x)) continue;
    if (auto s = face_sweep_of(f, n, kBspSameEndpoint)) out.push_back(std::move(*s));
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

// Appends `sweep` to `out`, cut into strips at most `spacing.piece` long when that is > 0, then
// with `spacing.crossed` its crossed sweep, cut the same way (AdaptiveSpacing).
void add_sweep(std::vector<FaceSweep>& out, const FaceSweep& sweep,
               const AdaptiveSpacing& spacing) {
  for (const FaceSweep& family : spacing.crossed
                                     ? std::vector<FaceSweep>{sweep, crossed_sweep(sweep)}
                                     : std::vector<FaceSweep>{sweep}) {
    if (!(spacing.piece > 0)) {
      out.push_back(family);
      continue;
    }
    for (FaceSweep& s : sweep_strips(family, spacing.piece)) out.push_back(std::move(s));
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

namespace {

// The vertex mean of a convex polytope's faces (a point inside it).
Vec3 polytope_centre(const ConvexPolytope& p) {
  Vec3 c{0, 0, 0};
  size_t n = 0;
  for (const std::vector<Vec3>& f : p.faces)
    for (const Vec3& v : f) {
      c = c + v;
      ++n;
    }
  return c * (1.0 / double(std::max<size_t>(n, 1)));
}

// A portal's runs (add_portal_runs): its segments (Quake coordinates), the first `edges` of them
// its clear part's edges when no triangle lies on it (those may share a run with other portals'),
// and its sweep.
struct PortalRuns {
  bool swept = false;
  std::vector<Segment> segs;
  size_t edges = 0;
  std::optional<FaceSweep> sweep;
};

// Where open portals meet along a line, their clear parts' edges lie within a few clearances of
// one another (each is inset from the others' planes): one run on the first of them, split by
// each such portal's plane (Segment::run_planes), serves them all. A group is an edge and up to
// kMaxSidePlanes - 1 edges of other portals whose ends lie within kSharedRunEdgeDistance of its
// ends (either way round), found in portal and edge order; each member takes the first's ends,
// and no bound (the whole scene: a bound of each group, the union of its portals', would be one
// more tree for every cell that uses it, which cost more than the restriction saved on the
// shared runs). Deterministic.
void share_portal_edges(const std::vector<BspPortal>& portals, std::vector<PortalRuns>& runs) {
  static_assert(2 * kSharedRunEdgeDistance < 1.0, "a group's midpoints lie in adjacent cells");
  using Cell = std::array<int64_t, 3>;
  auto cell_of = [](Vec3 p) {
    return Cell{int64_t(std::floor(p.x)), int64_t(std::floor(p.y)), int64_t(std::floor(p.z))};
  };
  struct Member {
    uint32_t portal, edge;
  };
  std::vector<std::vector<Member>> groups;
  std::map<Cell, std::vector<uint32_t>> by_cell;  // groups by their first edge's midpoint
  auto close = [](Vec3 a, Vec3 b) { return length(a - b) <= kSharedRunEdgeDistance; };
  for (uint32_t i = 0; i < runs.size(); ++i)
    for (uint32_t e = 0; e < runs[i].edges; ++e) {
      const Segment& s = runs[i].segs[e];
      const Cell c = cell_of((s.from + s.to) * 0.5);
      std::optional<uint32_t> found;
      for (int64_t dx = -1; dx <= 1 && !found; ++dx)
        for (int64_t dy = -1; dy <= 1 && !found; ++dy)
          for (int64_t dz = -1; dz <= 1 && !found; ++dz) {
            const auto it = by_cell.find(Cell{c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == by_cell.end()) continue;
            for (uint32_t g : it->second) {
              const std::vector<Member>& m = groups[g];
              const Segment& f = runs[m[0].portal].segs[m[0].edge];
              if (m.size() < kMaxSidePlanes &&
                  std::none_of(m.begin(), m.end(), [&](Member x) { return x.portal == i; }) &&
                  ((close(s.from, f.from) && close(s.to, f.to)) ||
                   (close(s.from, f.to) && close(s.to, f.from)))) {
                found = g;
                break;
              }
            }
          }
      if (found) {
        groups[*found].push_back({i, e});
      } else {
        by_cell[c].push_back(uint32_t(groups.size()));
        groups.push_back({{i, e}});
      }
    }
  for (const std::vector<Member>& m : groups) {
    if (m.size() < 2) continue;
    const Segment first = runs[m[0].portal].segs[m[0].edge];
    std::array<Vec3, kMaxSidePlanes> planes{};
    for (size_t k = 0; k < m.size(); ++k) planes[k] = portals[m[k].portal].normal;
    for (size_t k = 0; k < m.size(); ++k) {
      PortalRuns& r = runs[m[k].portal];
      Segment& s = r.segs[m[k].edge];
      s.from = first.from;
      s.to = first.to;
      s.run_planes = planes;
      s.run_plane = int(k);
    }
  }
}

// The portal runs of the cells (BspSweep::Portals, bsp_leaf_cells): each portal's edges and
// chords, or its sweep, for each of its two leaves that is a cell of `cells`, with the leaf's side,
// open portals' edges shared with options.share_edges (share_portal_edges). With options.bound,
// each portal's runs are restricted to its bound (bsp_bound.h), but for the shared edges.
void add_portal_runs(const QuakeBsp& bsp, const std::vector<BspLeafPiece>& pieces,
                     const std::vector<uint32_t>& all, const BspCellOptions& options,
                     const Scene& scene, ViewCells& cells) {
  // Each leaf's volume, when it is one piece (a leaf of several keeps no clearance from its
  // planes: its portals are swept whole on its side).
  std::vector<const ConvexPolytope*> volume(cells.layout.leaf_cell.size(), nullptr);
  std::vector<uint8_t> pieces_of(volume.size(), 0);
  for (const BspLeafPiece& piece : pieces)
    if (!piece.volume.empty() && piece.leaf < volume.size()) {
      volume[piece.leaf] = &piece.volume;
      pieces_of[piece.leaf] = uint8_t(std::min(2, pieces_of[piece.leaf] + 1));
    }
  const ConvexPolytope none;
  const double clearance = kNearClearanceFactor * options.near;
  const std::vector<BspPortal> portals = bsp_leaf_portals(pieces, all);
  const bool bounded = options.bound != BspBound::None;
  if (bounded) {
    cells.bound_leaves = bsp_portal_bound_leaves(bsp, portals, options.bound);
    cells.leaf_triangles = bsp_leaf_triangles(bsp, scene);
  }
  cells.segment_portal.resize(cells.segments.size());
  cells.sweep_portal.resize(cells.sweeps.size());
  std::vector<PortalRuns> runs(portals.size());
  for (size_t index = 0; index < portals.size(); ++index) {
    const BspPortal& p = portals[index];
    const BspPortalCover cover = bsp_portal_cover(p, scene);
    if (cover.closed) continue;  // each side sees the surface only
    auto side_volume = [&](int s) -> const ConvexPolytope& {
      const uint32_t l = p.leaves[s];
      return pieces_of[l] == 1 ? *volume[l] : none;
    };
    const std::vector<Vec3> clear =
        bsp_portal_clear_part(p, side_volume(0), side_volume(1), clearance);
    if (clear.empty()) continue;  // nothing of it is clear of the walls: only they are seen
    PortalRuns& r = runs[index];
    r.swept = true;
    std::vector<Segment> whole;  // Quake coordinates
    for (size_t i = 0; i < clear.size(); ++i) {
      const Vec3 a = clear[i], b = clear[(i + 1) % clear.size()];
      if (length(b - a) > kBspSameEndpoint) whole.push_back({a, b});
    }
    r.sweep = face_sweep_of(clear, p.normal, kBspSameEndpoint);
    // A partly covered portal is swept evenly (at the adaptive sweep's floor spacing when the
    // bake's sweep is adaptive, whose chords are whole), its segments cut to the open part.
    const double spacing = !options.adaptive     ? options.face_spacing
                           : cover.parts.empty() ? 0.0
                                                 : options.adaptive->floor;
    if (cover.parts.empty()) r.edges = whole.size();
    if (r.sweep && spacing > 0) {
      const std::vector<Segment> c = even_chords(*r.sweep, spacing, kBspSameEndpoint);
      whole.insert(whole.end(), c.begin(), c.end());
    }
    if (!cover.parts.empty()) r.sweep.reset();
    for (const Segment& s : whole)
      for (const Segment& piece : bsp_portal_open_pieces(s, p, cover, clearance, kBspSameEndpoint))
        r.segs.push_back(piece);
    assert(!cover.parts.empty() || r.segs.size() == whole.size());  // the edges come first
  }
  if (options.share_edges) share_portal_edges(portals, runs);
  for (size_t index = 0; index < portals.size(); ++index) {
    const BspPortal& p = portals[index];
    const PortalRuns& r = runs[index];
    if (!r.swept) continue;
    const Vec3 normal = quake_to_scene(p.normal);
    for (int side = 0; side < 2; ++side) {
      const uint32_t c = cells.layout.leaf_cell[p.leaves[side]];
      if (c == pvs::kNoCell) continue;  // a leaf not baked
      for (const Segment& s : r.segs) {
        Segment out{quake_to_scene(s.from), quake_to_scene(s.to), normal, side};
        for (size_t k = 0; k < s.run_planes.size(); ++k)
          out.run_planes[k] = quake_to_scene(s.run_planes[k]);
        out.run_plane = s.run_plane;
        cells.segments[c].push_back(out);
      }
      if (r.sweep && options.adaptive) {
        FaceSweep f = scene_sweep(*r.sweep);
        f.side_normal = normal;
        f.side = side;
        add_sweep(cells.sweeps[c], f, *options.adaptive);
      }
      cells.segment_portal[c].resize(cells.segments[c].size(), uint32_t(index));
      if (!cells.sweeps.empty())
        cells.sweep_portal[c].resize(cells.sweeps[c].size(), uint32_t(index));
    }
  }
}

}  // namespace

ViewCells bsp_leaf_cells(const QuakeBsp& bsp, const BspCellOptions& options, const Scene* scene) {
  assert(options.face_spacing >= 0);
  const bool portals = options.sweep == BspSweep::Portals;
  if (portals && !scene)
    throw std::invalid_argument("bsp_leaf_cells: a portal sweep needs the map's scene");
  if (options.bound != BspBound::None && !portals)
    throw std::invalid_argument("bsp_leaf_cells: a bound restricts the portal sweep's runs only");
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
  if (options.adaptive) cells.sweeps.resize(leaves.size());
  uint32_t thin = 0, uninset = 0, clipped = 0;
  std::vector<double> near_limit(leaves.size(), std::numeric_limits<double>::infinity());
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(bsp);
  if (portals) {
    add_portal_runs(bsp, pieces, all, options, *scene, cells);
    cells.own.resize(leaves.size());
    cells.regions.resize(leaves.size());
    cells.shared_runs = true;
  }
  for (const BspLeafPiece& piece : pieces) {
    const uint32_t c = cells.layout.leaf_cell[piece.leaf];
    if (c == pvs::kNoCell || piece.volume.empty()) continue;
    const BspViewRegion region = bsp_leaf_view_region(piece.volume, options.near);
    if (region.inset < kBspLeafInset) ++thin;
    if (region.inset == 0) ++uninset;
    if (region.near_limit < options.near) {
      ++clipped;
      near_limit[c] = std::min(near_limit[c], region.near_limit);
    }
    if (portals) {
      const Vec3 eye = quake_to_scene(polytope_centre(region.volume));
      if (cells.regions[c].empty()) cells.regions[c] = polytope_to_scene(region.volume);
      std::vector<ViewCells::OwnTriangle>& own = cells.own[c];
      for (const VolumeTriangle& t : bsp_volume_triangles(*scene, polytope_to_scene(piece.volume)))
        own.push_back({t.tri, eye, (t.point - eye) * (1.0 / length(t.point - eye))});
      continue;
    }
    std::vector<Segment> s =
        bsp_region_segments(region.volume, options.adaptive ? 0.0 : options.face_spacing);
    cells.segments[c].insert(cells.segments[c].end(), s.begin(), s.end());
    if (options.adaptive)
      for (const FaceSweep& f : region_sweeps(region.volume))
        add_sweep(cells.sweeps[c], scene_sweep(f), *options.adaptive);
  }
  for (std::vector<ViewCells::OwnTriangle>& own : cells.own) {  // a leaf of several pieces
    std::stable_sort(own.begin(), own.end(),
                     [](const auto& a, const auto& b) { return a.tri < b.tri; });
    own.erase(std::unique(own.begin(), own.end(),
                          [](const auto& a, const auto& b) { return a.tri == b.tri; }),
              own.end());
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
      {"sweep", portals ? "portals" : "faces"},
      {"face_spacing_units", "quake"},
      {"region",
       "leaf volume inset by inset units (halved down to the larger of min_inset and "
       "clearance for thin leaves, then clearance; a leaf thinner than twice the clearance by "
       "half its largest inset, its near distance clipped to that over clearance_factor); "
       "sweep faces: its edges and chords of each face parallel to its longest edge at most "
       "face_spacing apart; sweep portals: each portal's edges and chords, directions leaving "
       "the leaf, and the triangles on or in the leaf's volume"},
      {"inset", kBspLeafInset},
      {"min_inset", kBspLeafMinInset},
      {"clearance_factor", kNearClearanceFactor},
      {"clearance", kNearClearanceFactor * options.near},
      {"leaves_inset_less", thin},
      {"leaves_not_inset", uninset},
      {"leaves_near_clipped", clipped},
      {"bsp_models", options.scene.bsp_models == BspModels::all ? "all" : "world"},
      {"bsp_liquids", liquids},
      {"bound", options.bound == BspBound::Portals  ? "portals"
                : options.bound == BspBound::MapVis ? "map-vis"
                                                    : "none"}};
  if (portals) d["portal_edges"] = options.share_edges ? "shared" : "own";
  if (!cells.bound_leaves.empty()) {
    double leaves_sum = 0;
    for (const std::vector<uint32_t>& b : cells.bound_leaves) leaves_sum += double(b.size());
    d["bound_leaves_mean"] = leaves_sum / double(cells.bound_leaves.size());
  }
  if (options.adaptive) {
    d["chord_coarse"] = options.adaptive->coarse;
    d["chord_floor"] = options.adaptive->floor;
    d["chord_piece"] = options.adaptive->piece;
    d["chord_tiles"] = chord_tiles_name(options.adaptive->tiles);
    if (options.adaptive->tiles != ChordTiles::All) {
      d["chord_tile_margin"] = kChordTileMargin;
      d["chord_tile_size"] = options.adaptive->tile_size;
    }
    d["chord_new"] = options.adaptive->new_to_family ? "family" : "neighbours";
    if (options.adaptive->crossed) {
      d["chord_crossed"] = true;
      d["chord_cross_floor"] = options.adaptive->crossed_floor_or_floor();
    }
  }
  cells.description = d.dump();
  return cells;
}

}  // namespace vislib
