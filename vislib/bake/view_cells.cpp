// view_cells.cpp: grid and walkable view cells, and the placement that chooses between them.
#include "vislib/bake/view_cells.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "vislib/base/random.h"
#include "vislib/base/tolerances.h"

namespace vislib {

pvs::Box to_pvs_box(const Box3& b) {
  pvs::Box out;
  for (int a = 0; a < 3; ++a) {
    out.min[a] = b.min[a];
    out.max[a] = b.max[a];
  }
  return out;
}

Box3 to_box3(const pvs::Box& b) {
  Box3 out;
  out.min = {b.min[0], b.min[1], b.min[2]};
  out.max = {b.max[0], b.max[1], b.max[2]};
  return out;
}

namespace {

nlohmann::json box_json(const Box3& b) {
  return {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
}

}  // namespace

ViewCells grid_cells(const Box3& box, uint32_t nx, uint32_t ny, uint32_t nz,
                     const std::optional<EyeBand>& eye) {
  assert(!box.empty() && nx >= 1 && ny >= 1 && nz >= 1);
  ViewCells cells;
  pvs::CellLayout& L = cells.layout;
  L.kind = pvs::LayoutKind::Grid;
  L.grid_box = to_pvs_box(box);
  L.nx = nx;
  L.ny = ny;
  L.nz = nz;
  if (eye) {
    assert(eye->lo <= eye->hi);
    L.eye_lo = eye->lo;
    L.eye_hi = eye->hi;
  } else {
    // The view region is the cell: the band is the height of the first cell (the file stores
    // one band for all cells; other cells' heights differ from it by rounding at most).
    pvs::Box first = L.cell_box(0);
    L.eye_lo = 0;
    L.eye_hi = first.max[1] - first.min[1];
  }
  nlohmann::json d = {{"kind", "grid"}, {"box", box_json(box)}, {"grid", {nx, ny, nz}}};
  if (eye) d["eye_height"] = {eye->lo, eye->hi};
  cells.description = d.dump();
  return cells;
}

ViewCells grid_cells_by_size(const Box3& box, double cell_size, const std::optional<EyeBand>& eye) {
  assert(cell_size > 0);
  uint32_t n[3];
  for (int a = 0; a < 3; ++a)
    n[a] = uint32_t(std::max(1.0, std::ceil((box.max[a] - box.min[a]) / cell_size)));
  ViewCells cells = grid_cells(box, n[0], n[1], n[2], eye);
  nlohmann::json d = nlohmann::json::parse(cells.description);
  d["cell_size"] = cell_size;
  cells.description = d.dump();
  return cells;
}

namespace {

// A point of a clipped polygon (3D, clipped in x and z).
using Polygon = std::vector<Vec3>;

// Keeps the part of `poly` with sign * (p[axis] - value) >= 0.
Polygon clip(const Polygon& poly, int axis, double value, double sign) {
  Polygon out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    double da = sign * (a[axis] - value), db = sign * (b[axis] - value);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      double t = da / (da - db);
      Vec3 p = lerp(a, b, t);
      p[axis] = value;  // exactly on the plane
      out.push_back(p);
    }
  }
  return out;
}

double area_xz(const Polygon& poly) {
  double s = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    s += a.x * b.z - b.x * a.z;
  }
  return 0.5 * std::fabs(s);
}

// Height of triangle `c` (non-vertical) above the point (x, z), if (x, z) lies in its xz
// projection (edges included).
std::optional<double> height_at(const std::array<Vec3, 3>& c, double x, double z) {
  auto edge = [&](const Vec3& p, const Vec3& q) {
    return (q.x - p.x) * (z - p.z) - (q.z - p.z) * (x - p.x);
  };
  double e0 = edge(c[0], c[1]), e1 = edge(c[1], c[2]), e2 = edge(c[2], c[0]);
  bool inside = (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
  if (!inside) return std::nullopt;
  Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
  if (n.y == 0) return std::nullopt;
  return c[0].y - (n.x * (x - c[0].x) + n.z * (z - c[0].z)) / n.y;
}

struct FloorPiece {
  double lo, hi;
};

std::string point_text(Vec3 p) {
  char text[96];
  std::snprintf(text, sizeof text, "%g,%g,%g", p.x, p.y, p.z);
  return text;
}

// The starts without floor: refused as WalkableOptions::required_starts says.
void check_start_floors(const WalkableOptions& o, const ReachableFloor& reach) {
  const WalkAgent& a = o.agent;
  char agent[160];
  std::snprintf(agent, sizeof agent, "agent height %g, radius %g, step %g; slope limit %g degrees",
                a.height, a.radius, a.step, o.max_slope_degrees);
  bool any = false;
  for (size_t k = 0; k < o.starts.size(); ++k) {
    any = any || reach.start_floors[k].has_value();
    if (o.required_starts && !reach.start_floors[k])
      throw PlacementError(PlacementProblem::StartWithoutFloor,
                           "start " + point_text(o.starts[k].point) + " (" + o.starts[k].source +
                               ") has no walkable floor under it (" + agent + ")");
  }
  if (!any)
    throw PlacementError(
        PlacementProblem::StartWithoutFloor,
        "none of the " + std::to_string(o.starts.size()) +
            " starts has walkable floor under it (first: " + point_text(o.starts[0].point) + ", " +
            o.starts[0].source + "; " + agent + ")");
}

}  // namespace

ViewCells walkable_cells(const Scene& scene, const WalkableOptions& options) {
  assert(options.cell_size > 0 && options.eye.lo <= options.eye.hi);
  const double S = options.cell_size;
  Box3 region = options.clip ? *options.clip : scene.bounds();
  ViewCells cells;
  cells.layout.kind = pvs::LayoutKind::Boxes;
  nlohmann::json d = {{"kind", "walkable"},
                      {"cell_size", S},
                      {"eye_height", {options.eye.lo, options.eye.hi}},
                      {"max_slope_degrees", options.max_slope_degrees},
                      {"require_headroom", options.require_headroom}};
  if (options.clockwise_front) d["front_faces"] = "clockwise";
  if (options.clip) d["clip"] = box_json(*options.clip);
  d["rule"] = options.starts.empty() ? "every floor level with headroom"
                                     : "floor levels an agent can stand on, reachable from the "
                                       "starts by steps and drops";
  // Reachability: the floor the agent can stand on, from the starts.
  std::optional<ReachableFloor> reach;
  if (!options.starts.empty() && scene.triangle_count() > 0) {
    ReachOptions ro;
    ro.agent = options.agent;
    ro.max_slope_degrees = options.max_slope_degrees;
    ro.clockwise_front = options.clockwise_front;
    ro.starts = options.starts;
    ro.voxel = S / 4;
    if (options.agent.radius > 0) ro.voxel = std::min(ro.voxel, options.agent.radius / 2);
    ro.state = options.state;
    reach = reachable_floor(scene, ro);
    check_start_floors(options, *reach);
  }
  if (!options.starts.empty()) {
    nlohmann::json starts = nlohmann::json::array();
    for (size_t k = 0; k < options.starts.size(); ++k) {
      const WalkStart& st = options.starts[k];
      nlohmann::json floor = nullptr;
      if (reach && reach->start_floors[k]) floor = *reach->start_floors[k];
      starts.push_back({{"point", {st.point.x, st.point.y, st.point.z}},
                        {"source", st.source},
                        {"floor", floor}});
    }
    d["agent"] = {{"height", options.agent.height},
                  {"radius", options.agent.radius},
                  {"step", options.agent.step}};
    d["starts"] = starts;
    if (reach) d["voxel"] = {{"side", reach->voxel}, {"height", reach->voxel_height}};
  }
  cells.description = d.dump();
  if (region.empty() || scene.triangle_count() == 0) return cells;

  const uint32_t nx = uint32_t(std::max(1.0, std::ceil((region.max.x - region.min.x) / S)));
  const uint32_t nz = uint32_t(std::max(1.0, std::ceil((region.max.z - region.min.z) / S)));
  auto col_x0 = [&](uint32_t i) { return region.min.x + S * double(i); };
  auto col_z0 = [&](uint32_t k) { return region.min.z + S * double(k); };
  auto col_x1 = [&](uint32_t i) {
    return std::min(region.min.x + S * double(i + 1), region.max.x);
  };
  auto col_z1 = [&](uint32_t k) {
    return std::min(region.min.z + S * double(k + 1), region.max.z);
  };

  // Bin every non-vertical triangle by its xz bounding box; mark floors.
  std::vector<std::vector<uint32_t>> columns(size_t(nx) * nz);
  std::vector<uint8_t> is_floor(scene.triangle_count(), 0);
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    auto c = scene.corners(t, options.state);
    Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
    double len = length(n);
    if (!(len > 0) || n.y == 0) continue;
    is_floor[t] = floor_triangle(c, options.max_slope_degrees, options.clockwise_front);
    double x0 = std::min({c[0].x, c[1].x, c[2].x}), x1 = std::max({c[0].x, c[1].x, c[2].x});
    double z0 = std::min({c[0].z, c[1].z, c[2].z}), z1 = std::max({c[0].z, c[1].z, c[2].z});
    if (x1 < region.min.x || x0 > region.max.x || z1 < region.min.z || z0 > region.max.z) continue;
    auto index = [&](double v, double lo, uint32_t count) {
      double f = std::floor((v - lo) / S);
      return uint32_t(std::clamp(f, 0.0, double(count - 1)));
    };
    for (uint32_t k = index(z0, region.min.z, nz); k <= index(z1, region.min.z, nz); ++k)
      for (uint32_t i = index(x0, region.min.x, nx); i <= index(x1, region.min.x, nx); ++i)
        columns[size_t(k) * nx + i].push_back(t);
  }

  const double up = options.clockwise_front ? -1 : 1;  // the sign of a front normal's y facing up
  const double min_area = kMinFloorAreaFraction * S * S;
  const double tol = kFloorHeightTolerance * S;
  for (uint32_t k = 0; k < nz; ++k) {
    for (uint32_t i = 0; i < nx; ++i) {
      const auto& tris = columns[size_t(k) * nx + i];
      const double x0 = col_x0(i), x1 = col_x1(i), z0 = col_z0(k), z1 = col_z1(k);
      std::vector<FloorPiece> pieces;
      for (uint32_t t : tris) {
        if (!is_floor[t]) continue;
        auto c = scene.corners(t, options.state);
        Polygon p = {c[0], c[1], c[2]};
        p = clip(p, 0, x0, 1);
        p = clip(p, 0, x1, -1);
        p = clip(p, 2, z0, 1);
        p = clip(p, 2, z1, -1);
        if (p.size() < 3 || !(area_xz(p) > min_area)) continue;
        FloorPiece piece{INFINITY, -INFINITY};
        for (const Vec3& v : p) {
          piece.lo = std::min(piece.lo, v.y);
          piece.hi = std::max(piece.hi, v.y);
        }
        if (piece.hi < region.min.y || piece.lo > region.max.y) continue;
        pieces.push_back(piece);
      }
      if (pieces.empty()) continue;
      std::sort(pieces.begin(), pieces.end(), [](const FloorPiece& a, const FloorPiece& b) {
        return a.lo != b.lo ? a.lo < b.lo : a.hi < b.hi;
      });
      std::vector<FloorPiece> levels;
      for (const FloorPiece& p : pieces) {
        if (!levels.empty() && p.lo <= levels.back().hi + options.eye.hi)
          levels.back().hi = std::max(levels.back().hi, p.hi);
        else
          levels.push_back(p);
      }
      for (const FloorPiece& level : levels) {
        if (options.require_headroom) {
          bool open = false;
          for (int sz = 0; sz < 4 && !open; ++sz) {
            for (int sx = 0; sx < 4 && !open; ++sx) {
              double x = x0 + (x1 - x0) * (sx + 0.5) / 4, z = z0 + (z1 - z0) * (sz + 0.5) / 4;
              for (uint32_t t : tris) {
                if (!is_floor[t]) continue;
                auto f = height_at(scene.corners(t, options.state), x, z);
                if (!f || *f < level.lo - tol || *f > level.hi + tol) continue;
                bool blocked = false;
                for (uint32_t u : tris) {
                  if (u == t) continue;
                  auto c = scene.corners(u, options.state);
                  auto h = height_at(c, x, z);
                  if (!h) continue;
                  bool facing_down = cross(c[1] - c[0], c[2] - c[0]).y * up < 0;
                  if ((*h > *f + tol && *h <= *f + options.eye.lo) ||
                      (facing_down && *h >= *f - tol && *h <= *f + options.eye.lo)) {
                    blocked = true;
                    break;
                  }
                }
                if (!blocked) {
                  open = true;
                  break;
                }
              }
            }
          }
          if (!open) continue;
        }
        if (reach) {
          const double t = reach->voxel + reach->voxel_height;
          if (!reach->any_in(x0, x1, z0, z1, level.lo - t, level.hi + t)) continue;
        }
        pvs::Box b;
        b.min[0] = x0;
        b.max[0] = x1;
        b.min[2] = z0;
        b.max[2] = z1;
        b.min[1] = level.lo + options.eye.lo;
        b.max[1] = level.hi + options.eye.hi;
        cells.layout.boxes.push_back(b);
      }
    }
  }
  return cells;
}

namespace {

// Placed cells whose runs are the perimeters of their eye band at `levels` heights; a choice other
// than the paper's is recorded in the description ("band_levels").
// Records `key`: `value` in the cells' description (a JSON object).
void describe(ViewCells& cells, const char* key, const nlohmann::json& value) {
  nlohmann::json d = nlohmann::json::parse(cells.description);
  d[key] = value;
  cells.description = d.dump();
}

ViewCells with_band_levels(ViewCells cells, int levels) {
  assert(levels >= kPaperBandLevels);
  cells.band_levels = levels;
  if (levels != kPaperBandLevels) describe(cells, "band_levels", levels);
  return cells;
}

// The "cells" object of a bake's metadata (the cells' description); null when there is none.
nlohmann::json cells_description(const std::string& metadata) {
  const nlohmann::json md = nlohmann::json::parse(metadata, nullptr, false);
  if (!md.is_object() || !md.contains("cells") || !md["cells"].is_object()) return nullptr;
  return md["cells"];
}

ViewCells placed_cells(const Scene& scene, const CellPlacement& p) {
  const std::optional<Box3>& box = p.box;
  if (p.walkable) {
    if (p.grid)
      throw PlacementError(PlacementProblem::GridWithWalkable,
                           "grid counts cannot be combined with walkable cells");
    WalkableOptions w;
    w.cell_size = p.cell_size > 0 ? p.cell_size : 2.0;
    if (p.eye) w.eye = *p.eye;
    w.max_slope_degrees = p.max_slope_degrees;
    w.clockwise_front = p.clockwise_front;
    w.require_headroom = p.require_headroom;
    w.clip = box;
    w.starts = p.starts;
    w.required_starts = p.required_starts;
    w.agent.height = p.agent_height.value_or(w.eye.hi);
    w.agent.radius = p.agent_radius.value_or(w.eye.hi / 4);
    w.agent.step = p.agent_step.value_or(w.eye.hi / 4);
    const Box3 r = box ? *box : scene.bounds();
    auto columns = [&](double extent) { return std::max(1.0, std::ceil(extent / w.cell_size)); };
    if (!r.empty() && columns(r.max.x - r.min.x) * columns(r.max.z - r.min.z) > kMaxPlacedCells)
      throw PlacementError(PlacementProblem::TooManyColumns, "more than 10^7 walkable columns");
    const WalkAgent& a = w.agent;
    if (!w.starts.empty() && !(std::isfinite(a.height) && a.height > 0 && std::isfinite(a.radius) &&
                               a.radius >= 0 && std::isfinite(a.step) && a.step >= 0))
      throw PlacementError(PlacementProblem::BadAgent,
                           "the agent needs a finite height > 0, radius >= 0 and step >= 0");
    return walkable_cells(scene, w);
  }
  if (!box) throw PlacementError(PlacementProblem::NoBox, "a grid of cells needs a box");
  if (p.grid && p.cell_size > 0)
    throw PlacementError(PlacementProblem::GridAndCellSize,
                         "grid counts and a cell size cannot both be given");
  if (p.grid) {
    const std::array<uint32_t, 3>& g = *p.grid;
    assert(g[0] >= 1 && g[1] >= 1 && g[2] >= 1);
    if (double(g[0]) * double(g[1]) * double(g[2]) > kMaxPlacedCells)
      throw PlacementError(PlacementProblem::TooManyGridCells, "more than 10^7 grid cells");
    return grid_cells(*box, g[0], g[1], g[2], p.eye);
  }
  if (!(p.cell_size > 0))
    throw PlacementError(PlacementProblem::NoGridNorCellSize,
                         "a grid of cells needs grid counts or a cell size");
  double count = 1;
  for (int k = 0; k < 3; ++k)
    count *= std::max(1.0, std::ceil((box->max[k] - box->min[k]) / p.cell_size));
  if (count > kMaxPlacedCells)
    throw PlacementError(PlacementProblem::TooManySizedCells, "more than 10^7 grid cells");
  return grid_cells_by_size(*box, p.cell_size, p.eye);
}

}  // namespace

ViewCells place_view_cells(const Scene& scene, const CellPlacement& p) {
  ViewCells cells =
      with_band_levels(placed_cells(scene, p), p.band_levels.value_or(kPaperBandLevels));
  if (p.vertical_edges.value_or(p.walkable)) {
    cells.vertical_edges = true;
    describe(cells, "vertical_edges", true);
  }
  if (p.wall_traces.value_or(p.walkable)) {
    assert(p.near > 0);
    WallTraceOptions o;
    o.clearance = kWallTraceClearanceFactor * p.near;
    o.clockwise_front = p.clockwise_front;
    cells.wall_traces = wall_traces(scene, cells.layout, o);
    describe(cells, "wall_traces",
             {{"clearance", o.clearance},
              {"front_faces", o.clockwise_front ? "clockwise" : "counter-clockwise"}});
  }
  return cells;
}

bool vertical_edges_of(const std::string& metadata) {
  const nlohmann::json cells = cells_description(metadata);
  if (!cells.is_object()) return false;
  const auto v = cells.find("vertical_edges");
  return v != cells.end() && v->is_boolean() && v->get<bool>();
}

std::optional<WallTraceOptions> wall_traces_of(const std::string& metadata) {
  const nlohmann::json cells = cells_description(metadata);
  if (!cells.is_object()) return std::nullopt;
  const auto w = cells.find("wall_traces");
  if (w == cells.end() || !w->is_object() || !w->contains("clearance") ||
      !(*w)["clearance"].is_number())
    return std::nullopt;
  WallTraceOptions o;
  o.clearance = (*w)["clearance"].get<double>();
  if (!(o.clearance > 0) || !std::isfinite(o.clearance)) return std::nullopt;
  o.clockwise_front = w->value("front_faces", "") == "clockwise";
  return o;
}

int band_levels_of(const std::string& metadata) {
  const nlohmann::json cells = cells_description(metadata);
  if (!cells.is_object()) return kPaperBandLevels;
  const auto k = cells.find("band_levels");
  if (k == cells.end() || !k->is_number_integer()) return kPaperBandLevels;
  const int64_t levels = k->get<int64_t>();
  return levels >= kPaperBandLevels && levels <= kMaxBandLevels ? int(levels) : kPaperBandLevels;
}

}  // namespace vislib
