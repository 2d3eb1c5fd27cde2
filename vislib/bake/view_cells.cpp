// view_cells.cpp: grid and walkable view cells; a cell's visibility from the perimeter of the
// bottom and top rectangles of its eye band (paper §4.1 perimeter heuristic, §4.5 orientations).
#include "vislib/bake/view_cells.h"

#include <algorithm>
#include <cassert>
#include <cmath>
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
  if (options.clip) d["clip"] = box_json(*options.clip);
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
  const double cos_limit = std::cos(options.max_slope_degrees * M_PI / 180.0);
  std::vector<std::vector<uint32_t>> columns(size_t(nx) * nz);
  std::vector<uint8_t> is_floor(scene.triangle_count(), 0);
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    auto c = scene.corners(t, options.state);
    Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
    double len = length(n);
    if (!(len > 0) || n.y == 0) continue;
    is_floor[t] = n.y > 0 && n.y >= cos_limit * len;
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
                  bool facing_down = cross(c[1] - c[0], c[2] - c[0]).y < 0;
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

std::vector<Segment> cell_boundary_segments(const Box3& view_region) {
  Box3 bottom = view_region, top = view_region;
  bottom.max.y = bottom.min.y;
  top.min.y = top.max.y;
  std::vector<Segment> out = perimeter_segments(bottom);
  if (view_region.max.y > view_region.min.y) {
    auto t = perimeter_segments(top);
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

uint64_t cell_seed(uint64_t seed, uint32_t cell) {
  return Rng::derive(seed, cell);
}

std::vector<Box3> cell_rectangles(const pvs::CellLayout& layout, uint32_t cell) {
  const Box3 region = to_box3(layout.view_region(cell));
  Box3 bottom = region, top = region;
  bottom.max.y = region.min.y;
  top.min.y = region.max.y;
  if (region.max.y > region.min.y) return {bottom, top};
  return {bottom};
}

CellVisibility cell_visibility(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  Box3 region = to_box3(layout.view_region(cell));
  CellVisibility out;
  out.segments = cell_boundary_segments(region);
  const std::vector<Box3> rect = cell_rectangles(layout, cell);
  const int rects = int(rect.size());
  const uint64_t seed = cell_seed(options.seed, cell);
  for (int r = 0; r < rects; ++r) {
    RegionOptions o = options;
    o.seed = Rng::derive(seed, uint64_t(r));
    std::function<void(size_t, size_t)> run_done;
    if (progress)
      run_done = [&](size_t done, size_t total) {
        progress((double(r) + double(done) / double(std::max<size_t>(1, total))) / double(rects));
      };
    RegionResult rr = region_visibility(scene, rect[r], o, run_done);
    std::vector<uint32_t> merged;
    merged.reserve(out.triangles.size() + rr.visible.size());
    std::set_union(out.triangles.begin(), out.triangles.end(), rr.visible.begin(), rr.visible.end(),
                   std::back_inserter(merged));
    out.triangles = std::move(merged);
    merged.clear();
    std::set_union(out.spheres.begin(), out.spheres.end(), rr.visible_spheres.begin(),
                   rr.visible_spheres.end(), std::back_inserter(merged));
    out.spheres = std::move(merged);
    out.seconds += rr.seconds;
  }
  return out;
}

namespace {

// Möller-Trumbore: distance t > 0 along `d` from `o` to the triangle, if hit.
std::optional<double> ray_triangle(Vec3 o, Vec3 d, const std::array<Vec3, 3>& c) {
  Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
  Vec3 pv = cross(d, e2);
  double det = dot(e1, pv);
  if (det == 0 || !std::isfinite(det)) return std::nullopt;
  double inv = 1.0 / det;
  Vec3 tv = o - c[0];
  double u = dot(tv, pv) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  Vec3 qv = cross(tv, e1);
  double v = dot(d, qv) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  double t = dot(e2, qv) * inv;
  if (!(t > 0)) return std::nullopt;
  return t;
}

std::array<Vec3, kEnclosureRays> enclosure_directions() {
  std::array<Vec3, kEnclosureRays> d;
  int k = 0;
  for (int a = 0; a < 3; ++a)
    for (int s = -1; s <= 1; s += 2) {
      Vec3 v{0, 0, 0};
      v[a] = s;
      d[k++] = v;
    }
  for (int sx = -1; sx <= 1; sx += 2)
    for (int sy = -1; sy <= 1; sy += 2)
      for (int sz = -1; sz <= 1; sz += 2)
        d[k++] = Vec3{double(sx), double(sy), double(sz)} * (1 / std::sqrt(3.0));
  // Tilt every direction by fixed small rotations about y then x (0.1 and 0.07 rad).
  const double a = 0.1, b = 0.07;
  for (Vec3& v : d) {
    Vec3 r{std::cos(a) * v.x + std::sin(a) * v.z, v.y, -std::sin(a) * v.x + std::cos(a) * v.z};
    v = {r.x, std::cos(b) * r.y - std::sin(b) * r.z, std::sin(b) * r.y + std::cos(b) * r.z};
  }
  return d;
}

}  // namespace

bool point_enclosed(const Scene& scene, Vec3 p, size_t state) {
  static const std::array<Vec3, kEnclosureRays> dirs = enclosure_directions();
  int back = 0;
  for (const Vec3& d : dirs) {
    double best = INFINITY;
    bool best_back = false;
    for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
      auto c = scene.corners(t, state);
      auto hit = ray_triangle(p, d, c);
      if (hit && *hit < best) {
        best = *hit;
        best_back = dot(cross(c[1] - c[0], c[2] - c[0]), d) > 0;
      }
    }
    if (!std::isfinite(best)) return false;  // escapes
    back += best_back;
  }
  return 2 * back > kEnclosureRays;
}

CellFreeSpace cell_free_space(const Scene& scene, const Box3& r, size_t state) {
  CellFreeSpace out;
  const Vec3 centre = (r.min + r.max) * 0.5;
  std::vector<Vec3> samples = {centre};
  for (int sz = 0; sz < 4; ++sz)
    for (int sx = 0; sx < 4; ++sx)
      samples.push_back({r.min.x + (r.max.x - r.min.x) * (sx + 0.5) / 4, centre.y,
                         r.min.z + (r.max.z - r.min.z) * (sz + 0.5) / 4});
  double best = INFINITY;
  for (size_t i = 0; i < samples.size(); ++i) {
    bool enclosed = point_enclosed(scene, samples[i], state);
    ++out.samples;
    out.enclosed += enclosed;
    if (i == 0) out.centre_enclosed = enclosed;
    double dist = length(samples[i] - centre);
    if (!enclosed && dist < best) {  // strict: the first of equally near samples wins
      best = dist;
      out.free_point = samples[i];
    }
  }
  return out;
}

}  // namespace vislib
