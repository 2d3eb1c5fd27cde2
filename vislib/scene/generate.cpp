// generate.cpp: the procedural test scenes of generate.h, modelled on Table 1 of the
// from-segment visibility paper (city for Manhattan/Medieval, Grass / Swaying Grass, Bouncing
// Spheres). Deterministic: vislib::Rng streams derived per block / patch, serial loops.
#include "vislib/scene/generate.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "vislib/base/random.h"

namespace vislib {

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------------
// City

struct Tier {
  double x0, x1, z0, z1, y0, y1;  // an axis-aligned box; tier t+1 stands on tier t, inset
};

struct Building {
  std::string name;
  std::vector<Tier> tiers;  // 1..3, bottom first
};

// Block layout and building shapes; independent of panel_size so that the triangle count can be
// searched over panel_size on a fixed layout.
std::vector<Building> city_layout(const CityOptions& o) {
  assert(o.blocks_x >= 1 && o.blocks_z >= 1 && o.lots_per_side >= 1);
  assert(o.block_size > 0 && o.street_width > 0);
  assert(o.min_height > 0 && o.min_height <= o.max_height);
  const double pitch = o.block_size + o.street_width;
  const double total_x = o.blocks_x * o.block_size + (o.blocks_x - 1) * o.street_width;
  const double total_z = o.blocks_z * o.block_size + (o.blocks_z - 1) * o.street_width;
  const double lot = o.block_size / o.lots_per_side;
  std::vector<Building> out;
  for (int bi = 0; bi < o.blocks_x; ++bi)
    for (int bj = 0; bj < o.blocks_z; ++bj) {
      Rng rng(Rng::derive(o.seed, uint64_t(bi) * uint64_t(o.blocks_z) + uint64_t(bj)));
      const double bx = -total_x / 2 + bi * pitch, bz = -total_z / 2 + bj * pitch;
      // Downtown: blocks near the centre reach higher.
      double cx = bx + o.block_size / 2, cz = bz + o.block_size / 2;
      double r = std::sqrt(cx * cx + cz * cz) /
                 (0.5 * std::sqrt(total_x * total_x + total_z * total_z) + 1e-9);
      double boost = 1.0 - 0.6 * std::min(r, 1.0);
      for (int li = 0; li < o.lots_per_side; ++li)
        for (int lj = 0; lj < o.lots_per_side; ++lj) {
          bool interior = li > 0 && lj > 0 && li + 1 < o.lots_per_side && lj + 1 < o.lots_per_side;
          double u_present = rng.uniform();
          if (interior && u_present < 0.5) continue;  // courtyard
          Tier t;
          t.x0 = bx + li * lot + rng.uniform(0.25, 1.0);
          t.x1 = bx + (li + 1) * lot - rng.uniform(0.25, 1.0);
          t.z0 = bz + lj * lot + rng.uniform(0.25, 1.0);
          t.z1 = bz + (lj + 1) * lot - rng.uniform(0.25, 1.0);
          if (t.x1 - t.x0 < 1.0 || t.z1 - t.z0 < 1.0) continue;  // lots too small for a building
          double u = rng.uniform();
          double h = o.min_height + (o.max_height - o.min_height) * std::pow(u, 1.5) * boost;
          t.y0 = 0;
          Building b;
          b.name = "building_" + std::to_string(bi) + "_" + std::to_string(bj) + "_" +
                   std::to_string(li * o.lots_per_side + lj);
          // Setbacks: tall buildings on large lots may get 1-2 inset tiers (the top one a tower).
          int tiers = 1;
          double minside = std::min(t.x1 - t.x0, t.z1 - t.z0);
          if (h > 20 && minside > 10 && rng.uniform() < 0.45) tiers = rng.uniform() < 0.5 ? 2 : 3;
          double base = tiers == 1 ? h : h * rng.uniform(0.35, 0.6);
          t.y1 = base;
          b.tiers.push_back(t);
          for (int k = 1; k < tiers; ++k) {
            Tier p = b.tiers.back(), n;
            double side = std::min(p.x1 - p.x0, p.z1 - p.z0);
            double inset = side * rng.uniform(0.1, 0.22);
            if (side - 2 * inset < 3) break;
            n.x0 = p.x0 + inset * rng.uniform(0.5, 1.5);
            n.x1 = p.x1 - inset * rng.uniform(0.5, 1.5);
            n.z0 = p.z0 + inset * rng.uniform(0.5, 1.5);
            n.z1 = p.z1 - inset * rng.uniform(0.5, 1.5);
            n.y0 = p.y1;
            double rest = h - p.y1;
            n.y1 = n.y0 +
                   (k + 1 == tiers ? rest * rng.uniform(0.8, 1.6) : rest * rng.uniform(0.4, 0.7));
            if (n.y1 - n.y0 < 2) n.y1 = n.y0 + 2;
            b.tiers.push_back(n);
          }
          out.push_back(std::move(b));
        }
    }
  return out;
}

int segments(double length, double panel) {
  if (panel <= 0) return 1;
  double n = std::round(length / panel);
  return n < 1 ? 1 : (n > 1e6 ? 1000000 : int(n));
}

struct TierGrid {
  int nx, nz, rows;
  int ring() const { return 2 * (nx + nz); }
};

TierGrid tier_grid(const Tier& t, double panel) {
  return {segments(t.x1 - t.x0, panel), segments(t.z1 - t.z0, panel), segments(t.y1 - t.y0, panel)};
}

uint64_t building_triangles(const Building& b, double panel) {
  uint64_t n = 0;
  for (size_t t = 0; t < b.tiers.size(); ++t) {
    TierGrid g = tier_grid(b.tiers[t], panel);
    n += 2ull * uint64_t(g.ring()) * uint64_t(g.rows);  // walls
    if (t == 0) n += uint64_t(g.ring());                // bottom fan
    if (t + 1 == b.tiers.size())
      n += uint64_t(g.ring());  // roof fan
    else
      n += uint64_t(g.ring()) + uint64_t(tier_grid(b.tiers[t + 1], panel).ring());  // ledge
  }
  return n;
}

struct GroundGrid {
  int nx, nz;
  double x0, x1, z0, z1;
};

GroundGrid ground_grid(const CityOptions& o) {
  const double total_x = o.blocks_x * o.block_size + (o.blocks_x - 1) * o.street_width;
  const double total_z = o.blocks_z * o.block_size + (o.blocks_z - 1) * o.street_width;
  GroundGrid g;
  g.x0 = -total_x / 2 - o.street_width;
  g.x1 = total_x / 2 + o.street_width;
  g.z0 = -total_z / 2 - o.street_width;
  g.z1 = total_z / 2 + o.street_width;
  double cell = (o.block_size + o.street_width) / 4;
  g.nx = segments(g.x1 - g.x0, cell);
  g.nz = segments(g.z1 - g.z0, cell);
  return g;
}

uint64_t layout_triangles(const std::vector<Building>& layout, const GroundGrid& g, double panel) {
  uint64_t n = 2ull * uint64_t(g.nx) * uint64_t(g.nz);
  for (const auto& b : layout) n += building_triangles(b, panel);
  return n;
}

// Appends a triangle with object id `obj`.
void add_tri(Scene& s, uint32_t a, uint32_t b, uint32_t c, uint32_t obj) {
  s.triangles.push_back({a, b, c});
  s.triangle_object.push_back(obj);
}

// Point `k` of a tier's ring: counter-clockwise order seen from below (+x along z0, +z along x1,
// -x along z1, -z along x0), starting at (x0, z0).
std::pair<double, double> ring_point(const Tier& t, const TierGrid& g, int k) {
  if (k < g.nx) return {t.x0 + (t.x1 - t.x0) * k / g.nx, t.z0};
  k -= g.nx;
  if (k < g.nz) return {t.x1, t.z0 + (t.z1 - t.z0) * k / g.nz};
  k -= g.nz;
  if (k < g.nx) return {t.x1 - (t.x1 - t.x0) * k / g.nx, t.z1};
  k -= g.nx;
  return {t.x0, t.z1 - (t.z1 - t.z0) * k / g.nz};
}

void add_building(Scene& s, const Building& b, double panel, uint32_t obj) {
  auto& pos = s.positions[0];
  std::vector<uint32_t> first_vertex;  // wall vertex (row r, ring k) = first + r * ring + k
  std::vector<TierGrid> grids;
  for (const auto& t : b.tiers) {
    TierGrid g = tier_grid(t, panel);
    first_vertex.push_back(uint32_t(pos.size()));
    grids.push_back(g);
    for (int r = 0; r <= g.rows; ++r) {
      double y = r == g.rows ? t.y1 : t.y0 + (t.y1 - t.y0) * r / g.rows;
      for (int k = 0; k < g.ring(); ++k) {
        auto [x, z] = ring_point(t, g, k);
        pos.push_back({x, y, z});
      }
    }
  }
  for (size_t ti = 0; ti < b.tiers.size(); ++ti) {
    const Tier& t = b.tiers[ti];
    const TierGrid& g = grids[ti];
    const int n = g.ring();
    auto v = [&](int r, int k) { return first_vertex[ti] + uint32_t(r * n + (k % n)); };
    // Walls: quad A=(r,k) B=(r,k+1) C=(r+1,k+1) D=(r+1,k) as (A,C,B) (A,D,C): outward.
    for (int r = 0; r < g.rows; ++r)
      for (int k = 0; k < n; ++k) {
        add_tri(s, v(r, k), v(r + 1, k + 1), v(r, k + 1), obj);
        add_tri(s, v(r, k), v(r + 1, k), v(r + 1, k + 1), obj);
      }
    const double cx = (t.x0 + t.x1) / 2, cz = (t.z0 + t.z1) / 2;
    if (ti == 0) {  // bottom fan, facing down
      uint32_t c = uint32_t(pos.size());
      pos.push_back({cx, t.y0, cz});
      for (int k = 0; k < n; ++k) add_tri(s, c, v(0, k), v(0, k + 1), obj);
    }
    if (ti + 1 == b.tiers.size()) {  // roof fan, facing up
      uint32_t c = uint32_t(pos.size());
      pos.push_back({cx, t.y1, cz});
      for (int k = 0; k < n; ++k) add_tri(s, c, v(g.rows, k + 1), v(g.rows, k), obj);
      continue;
    }
    // Ledge between this tier's top ring (outer) and the next tier's bottom ring (inner), facing
    // up: zip the two parallel polylines of each side by their fraction along the side.
    const TierGrid& gi = grids[ti + 1];
    const int ni = gi.ring();
    auto vi = [&](int k) { return first_vertex[ti + 1] + uint32_t(k % ni); };
    const int side_o[4] = {g.nx, g.nz, g.nx, g.nz}, side_i[4] = {gi.nx, gi.nz, gi.nx, gi.nz};
    int start_o = 0, start_i = 0;
    for (int side = 0; side < 4; ++side) {
      int i = 0, j = 0;
      const int m = side_o[side], q = side_i[side];
      while (i < m || j < q) {
        // Advance the polyline whose next point comes first along the side (outer on ties).
        bool outer = j == q || (i < m && int64_t(i + 1) * q <= int64_t(j + 1) * m);
        if (outer) {
          add_tri(s, v(g.rows, start_o + i), vi(start_i + j), v(g.rows, start_o + i + 1), obj);
          ++i;
        } else {
          add_tri(s, v(g.rows, start_o + i), vi(start_i + j), vi(start_i + j + 1), obj);
          ++j;
        }
      }
      start_o += m;
      start_i += q;
    }
  }
}

double choose_panel(const std::vector<Building>& layout, const GroundGrid& g, uint64_t target) {
  if (layout_triangles(layout, g, 0) >= target) return 0;
  // layout_triangles is non-increasing in the panel size: bisect on log(panel).
  double lo = std::log(0.02), hi = std::log(1e5);
  for (int it = 0; it < 80; ++it) {
    double mid = 0.5 * (lo + hi);
    if (layout_triangles(layout, g, std::exp(mid)) > target)
      lo = mid;
    else
      hi = mid;
  }
  double a = std::exp(lo), b = std::exp(hi);
  uint64_t na = layout_triangles(layout, g, a), nb = layout_triangles(layout, g, b);
  return (na - target) < (target - nb) ? a : b;
}

CityOptions resolve_city(const CityOptions& options, std::vector<Building>& layout, GroundGrid& g) {
  CityOptions o = options;
  if (o.target_triangles > 0 && o.auto_blocks) {
    // About 2,500 triangles per block leaves facades of a few meters per panel.
    double n = std::round(std::sqrt(double(o.target_triangles) / 2500.0));
    o.blocks_x = o.blocks_z = int(std::clamp(n, 1.0, 2000.0));
  }
  layout = city_layout(o);
  g = ground_grid(o);
  if (o.target_triangles > 0) o.panel_size = choose_panel(layout, g, o.target_triangles);
  return o;
}

}  // namespace

uint64_t city_triangle_count(const CityOptions& options) {
  std::vector<Building> layout = city_layout(options);
  return layout_triangles(layout, ground_grid(options), options.panel_size);
}

Scene generate_city(const CityOptions& options) {
  std::vector<Building> layout;
  GroundGrid g;
  CityOptions o = resolve_city(options, layout, g);
  Scene s;
  s.positions.resize(1);
  uint64_t tris = layout_triangles(layout, g, o.panel_size);
  s.triangles.reserve(tris);
  s.triangle_object.reserve(tris);
  // Ground: near-square cells, two upward triangles each.
  s.objects.push_back({"ground"});
  for (int j = 0; j <= g.nz; ++j)
    for (int i = 0; i <= g.nx; ++i)
      s.positions[0].push_back({i == g.nx ? g.x1 : g.x0 + (g.x1 - g.x0) * i / g.nx, 0.0,
                                j == g.nz ? g.z1 : g.z0 + (g.z1 - g.z0) * j / g.nz});
  auto gv = [&](int i, int j) { return uint32_t(j * (g.nx + 1) + i); };
  for (int j = 0; j < g.nz; ++j)
    for (int i = 0; i < g.nx; ++i) {
      add_tri(s, gv(i, j), gv(i, j + 1), gv(i + 1, j + 1), 0);
      add_tri(s, gv(i, j), gv(i + 1, j + 1), gv(i + 1, j), 0);
    }
  for (size_t bi = 0; bi < layout.size(); ++bi) {
    uint32_t obj = uint32_t(s.objects.size());
    s.objects.push_back({layout[bi].name});
    add_building(s, layout[bi], o.panel_size, obj);
    if (o.progress && bi % 256 == 0) o.progress(double(bi) / double(layout.size()));
  }
  assert(s.triangles.size() == tris);
  if (o.progress) o.progress(1.0);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Grass

namespace {

struct Terrain {
  int n;                  // n x n cells
  double x0, cell;        // square grid from (x0, x0), cell side
  std::vector<double> h;  // (n+1)^2 heights, row-major in z then x
  double height(int i, int j) const { return h[size_t(j) * size_t(n + 1) + size_t(i)]; }
  // Height of the triangulated surface at (x, z): each cell split along (i,j)-(i+1,j+1).
  double surface(double x, double z) const {
    double fx = (x - x0) / cell, fz = (z - x0) / cell;
    int i = std::clamp(int(std::floor(fx)), 0, n - 1),
        j = std::clamp(int(std::floor(fz)), 0, n - 1);
    double u = std::clamp(fx - i, 0.0, 1.0), w = std::clamp(fz - j, 0.0, 1.0);
    double h00 = height(i, j), h11 = height(i + 1, j + 1);
    if (u >= w) return h00 + u * (height(i + 1, j) - h00) + w * (h11 - height(i + 1, j));
    return h00 + w * (height(i, j + 1) - h00) + u * (h11 - height(i, j + 1));
  }
};

Terrain make_terrain(const GrassOptions& o) {
  Terrain t;
  t.n = segments(o.size, o.terrain_cell);
  t.x0 = -o.size / 2;
  t.cell = o.size / t.n;
  Rng rng(Rng::derive(o.seed, 0));
  double fx[3], fz[3], ph[3], amp[3] = {0.5, 0.3, 0.2};
  for (int k = 0; k < 3; ++k) {
    double wavelength = rng.uniform(30, 90), angle = rng.uniform(0, 2 * kPi);
    fx[k] = 2 * kPi * std::cos(angle) / wavelength;
    fz[k] = 2 * kPi * std::sin(angle) / wavelength;
    ph[k] = rng.uniform(0, 2 * kPi);
  }
  t.h.resize(size_t(t.n + 1) * size_t(t.n + 1));
  for (int j = 0; j <= t.n; ++j)
    for (int i = 0; i <= t.n; ++i) {
      double x = t.x0 + t.cell * i, z = t.x0 + t.cell * j, y = 0;
      for (int k = 0; k < 3; ++k) y += amp[k] * std::sin(fx[k] * x + fz[k] * z + ph[k]);
      t.h[size_t(j) * size_t(t.n + 1) + size_t(i)] = o.terrain_amplitude * y;
    }
  return t;
}

}  // namespace

Scene generate_grass(const GrassOptions& o) {
  assert(o.size > 0 && o.terrain_cell > 0 && o.patch_size > 0 && o.states >= 1);
  assert(o.blade_triangles >= 2 && o.blade_triangles <= 5 && o.wind_wavelength > 0);
  const Terrain terrain = make_terrain(o);
  const int K = o.states, T = o.blade_triangles;
  const uint64_t terrain_tris = 2ull * uint64_t(terrain.n) * uint64_t(terrain.n);
  uint64_t blades = uint64_t(std::llround(std::max(0.0, o.density) * o.size * o.size));
  if (o.target_triangles > 0)
    blades =
        o.target_triangles > terrain_tris ? (o.target_triangles - terrain_tris + T / 2) / T : 0;
  const uint64_t vertices = uint64_t(terrain.n + 1) * uint64_t(terrain.n + 1) + blades * (T + 2);
  assert(vertices < (1ull << 32));

  Scene s;
  s.positions.assign(size_t(K), {});
  for (auto& p : s.positions) p.reserve(vertices);
  s.triangles.reserve(terrain_tris + blades * T);
  s.triangle_object.reserve(terrain_tris + blades * T);
  s.objects.push_back({"terrain"});
  for (int j = 0; j <= terrain.n; ++j)
    for (int i = 0; i <= terrain.n; ++i) {
      Vec3 p{terrain.x0 + terrain.cell * i, terrain.height(i, j), terrain.x0 + terrain.cell * j};
      for (auto& state : s.positions) state.push_back(p);
    }
  auto tv = [&](int i, int j) { return uint32_t(j * (terrain.n + 1) + i); };
  for (int j = 0; j < terrain.n; ++j)
    for (int i = 0; i < terrain.n; ++i) {  // upward, split along (i,j)-(i+1,j+1) as surface()
      add_tri(s, tv(i, j), tv(i, j + 1), tv(i + 1, j + 1), 0);
      add_tri(s, tv(i, j), tv(i + 1, j + 1), tv(i + 1, j), 0);
    }

  const int np = segments(o.size, o.patch_size);
  const double patch = o.size / np;
  const uint64_t patches = uint64_t(np) * uint64_t(np);
  for (uint64_t pi = 0; pi < patches; ++pi) {
    const int ix = int(pi % uint64_t(np)), iz = int(pi / uint64_t(np));
    uint32_t obj = uint32_t(s.objects.size());
    s.objects.push_back({"grass_" + std::to_string(ix) + "_" + std::to_string(iz)});
    Rng rng(Rng::derive(o.seed, 1 + pi));
    const uint64_t count = blades / patches + (pi < blades % patches ? 1 : 0);
    for (uint64_t b = 0; b < count; ++b) {
      double x = terrain.x0 + patch * (ix + rng.uniform()),
             z = terrain.x0 + patch * (iz + rng.uniform());
      Vec3 base{x, terrain.surface(x, z), z};
      double yaw = rng.uniform(0, 2 * kPi);
      Vec3 face{std::cos(yaw), 0, std::sin(yaw)}, side{-std::sin(yaw), 0, std::cos(yaw)};
      double height = o.blade_height * rng.uniform(0.6, 1.4);
      double width = o.blade_width * rng.uniform(0.7, 1.3);
      double lean = rng.uniform(0.05, 0.35), stiffness = rng.uniform(0.7, 1.3);
      double jitter = rng.uniform(-0.3, 0.3);
      const uint32_t first = uint32_t(s.positions[0].size());
      for (int k = 0; k < K; ++k) {
        // Bend: rest lean over the blade's face plus the gust downwind (+x), as a small-angle
        // vector sum; the centre line is a circular arc of length `height` turning by `angle`.
        double gust =
            0.5 + 0.5 * std::sin(2 * kPi * (x / o.wind_wavelength - double(k) / K) + jitter);
        double bx = lean * face.x + o.wind_amplitude * stiffness * gust, bz = lean * face.z;
        double angle = std::min(std::sqrt(bx * bx + bz * bz), 1.4);
        Vec3 dir = angle > 0 ? Vec3{bx, 0, bz} * (1.0 / std::sqrt(bx * bx + bz * bz)) : Vec3{};
        for (int vi = 0; vi < T + 2; ++vi) {
          double sp = vi < 2 ? 0.0 : double(vi - 1) / T;
          double a = angle * sp;
          double horiz = angle > 1e-9 ? height * (1 - std::cos(a)) / angle : 0.0;
          double up = angle > 1e-9 ? height * std::sin(a) / angle : height * sp;
          Vec3 c = vi < 2 ? base : base + dir * horiz + Vec3{0, up, 0};
          double half = 0.5 * width * (1 - sp);
          s.positions[size_t(k)].push_back(vi % 2 == 0 ? c - side * half : c + side * half);
        }
      }
      for (int t = 0; t < T; ++t) {  // strip: consistent winding across the blade
        uint32_t a = first + uint32_t(t), b1 = a + 1, c = a + 2;
        if (t % 2 == 0)
          add_tri(s, a, b1, c, obj);
        else
          add_tri(s, b1, a, c, obj);
      }
    }
    if (o.progress && pi % 16 == 0) o.progress(double(pi) / double(patches));
  }
  if (o.progress) o.progress(1.0);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Bouncing spheres

namespace {

// Advances height y (centre) and vertical speed vy by dt under gravity g, bouncing on y = floor.
void fly_vertical(double& y, double& vy, double dt, double floor, double g, double restitution) {
  double left = dt;
  for (int bounces = 0; left > 0; ++bounces) {
    double drop = std::max(y - floor, 0.0);
    if (bounces > 10000 || (drop == 0 && vy <= 1e-3)) {  // at rest on the ground
      y = floor;
      vy = 0;
      return;
    }
    double hit = (vy + std::sqrt(vy * vy + 2 * g * drop)) / g;  // time to reach the floor
    if (hit >= left) {
      y = std::max(floor, y + vy * left - 0.5 * g * left * left);
      vy -= g * left;
      return;
    }
    left -= hit;
    y = floor;
    vy = -(vy - g * hit) * restitution;
  }
}

// Advances x with speed vx by dt between walls lo <= x <= hi (elastic reflections, closed form).
void fly_horizontal(double& x, double& vx, double dt, double lo, double hi) {
  double len = hi - lo;
  if (len <= 0) {
    x = lo;
    return;
  }
  double u = x + vx * dt - lo;
  double m = std::floor(u / len);
  double frac = std::clamp(u - m * len, 0.0, len);
  if (std::fmod(std::fabs(m), 2.0) == 0) {
    x = lo + frac;
  } else {
    x = hi - frac;
    vx = -vx;
  }
}

}  // namespace

Scene generate_spheres(const SphereOptions& o) {
  assert(o.count >= 0 && o.radius > 0 && o.states >= 1 && o.duration > 0 && o.gravity > 0);
  assert(o.area >= 2 * o.radius && o.restitution >= 0 && o.restitution <= 1 && o.max_height >= 0);
  Scene s;
  const size_t n = size_t(o.count), K = size_t(o.states);
  s.sphere_radius.assign(n, o.radius);
  s.sphere_centers.assign(K, std::vector<Vec3>(n));
  s.sphere_object.resize(n);
  s.objects.resize(n);
  const double lo = -o.area / 2 + o.radius, hi = o.area / 2 - o.radius;
  const double dt = K > 1 ? o.duration / double(K - 1) : 0;
  Rng rng(o.seed);
  for (size_t i = 0; i < n; ++i) {
    s.objects[i].name = "sphere" + std::to_string(i);
    s.sphere_object[i] = uint32_t(i);
    Vec3 p{rng.uniform(lo, hi), o.radius + rng.uniform(0, o.max_height), rng.uniform(lo, hi)};
    Vec3 v{rng.uniform(-o.speed, o.speed), rng.uniform(-o.speed, o.speed),
           rng.uniform(-o.speed, o.speed)};
    s.sphere_centers[0][i] = p;
    for (size_t k = 1; k < K; ++k) {
      fly_horizontal(p.x, v.x, dt, lo, hi);
      fly_horizontal(p.z, v.z, dt, lo, hi);
      fly_vertical(p.y, v.y, dt, o.radius, o.gravity, o.restitution);
      s.sphere_centers[k][i] = p;
    }
  }
  return s;
}

}  // namespace vislib
