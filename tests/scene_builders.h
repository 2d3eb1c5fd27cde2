// scene_builders.h: tiny scenes for semantic tests, built in code.
#pragma once

#include <utility>
#include <vector>

#include "vislib/base/random.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/scene.h"

namespace vislib_test {

// A scene of independent triangles (a soup), one object per triangle.
inline vislib::Scene soup(const std::vector<std::array<vislib::Vec3, 3>>& tris) {
  vislib::Scene s;
  s.positions.resize(1);
  for (const auto& t : tris) {
    uint32_t b = uint32_t(s.positions[0].size());
    for (const auto& p : t) s.positions[0].push_back(p);
    s.triangles.push_back({b, b + 1, b + 2});
    s.triangle_object.push_back(uint32_t(s.objects.size()));
    s.objects.push_back({"t" + std::to_string(s.objects.size())});
  }
  return s;
}

// A random soup of n triangles of size ~`size` around random centres in [-extent, extent]^3.
inline vislib::Scene random_soup(int n, uint64_t seed, double extent = 10, double size = 2) {
  vislib::Rng rng(seed);
  std::vector<std::array<vislib::Vec3, 3>> tris;
  for (int i = 0; i < n; ++i) {
    vislib::Vec3 c{rng.uniform(-extent, extent), rng.uniform(-extent, extent),
                   rng.uniform(-extent, extent)};
    std::array<vislib::Vec3, 3> t;
    for (auto& p : t)
      p = c + vislib::Vec3{rng.uniform(-size, size), rng.uniform(-size, size),
                           rng.uniform(-size, size)};
    tris.push_back(t);
  }
  return soup(tris);
}

// A generated city of 2 x 2 blocks with 4-unit panels (seed 3): walls of quads, each a fan of two
// triangles.
inline vislib::Scene panel_city() {
  vislib::CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  o.panel_size = 4;
  o.seed = 3;
  return vislib::generate_city(o);
}

// Case k of runs down panel_city()'s streets: the segment at eye height, from `rng`, k < 2 short
// (2 units), then long (16 units, crossing a building: boxes that straddle the segment); `o` gets
// N = 48 and, for odd k, a random cube orientation.
inline std::pair<vislib::Vec3, vislib::Vec3> panel_city_street(vislib::Rng& rng, int k,
                                                               vislib::SegmentOptions& o) {
  o.resolution = 48;
  if (k % 2) o.orientation = vislib::random_orientation(100 + uint64_t(k));
  const double len = k < 2 ? 2.0 : 16.0;
  const vislib::Vec3 v0{rng.uniform(-10, 10), 1.7, rng.uniform(-10, 10)};
  return {v0, v0 + vislib::Vec3{len * 0.6, 0.3, len * 0.8}};
}

// Appends an indexed quad (two triangles) a b c d (counter-clockwise) to `s` as one object.
inline void add_quad(vislib::Scene& s, vislib::Vec3 a, vislib::Vec3 b, vislib::Vec3 c,
                     vislib::Vec3 d) {
  if (s.positions.empty()) s.positions.resize(1);
  uint32_t base = uint32_t(s.positions[0].size());
  for (auto p : {a, b, c, d}) s.positions[0].push_back(p);
  uint32_t obj = uint32_t(s.objects.size());
  s.objects.push_back({"quad" + std::to_string(obj)});
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangle_object.push_back(obj);
  s.triangle_object.push_back(obj);
}

// An indexed n x n grid over [x0,x1] x [y0,y1] at depth z(x,y) with jittered interior vertices
// (shared vertices: a closed surface without cracks).
template <class ZFn>
void add_grid(vislib::Scene& s, int n, double x0, double x1, double y0, double y1, ZFn z,
              uint64_t seed, double jitter) {
  if (s.positions.empty()) s.positions.resize(1);
  vislib::Rng rng(seed);
  uint32_t base = uint32_t(s.positions[0].size());
  uint32_t obj = uint32_t(s.objects.size());
  s.objects.push_back({"grid" + std::to_string(obj)});
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = x0 + (x1 - x0) * i / n, y = y0 + (y1 - y0) * j / n;
      if (i > 0 && i < n) x += jitter * (rng.uniform() - 0.5) * (x1 - x0) / n;
      if (j > 0 && j < n) y += jitter * (rng.uniform() - 0.5) * (y1 - y0) / n;
      s.positions[0].push_back({x, y, z(x, y)});
    }
  auto at = [&](int i, int j) { return base + uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      s.triangle_object.push_back(obj);
      s.triangle_object.push_back(obj);
    }
}

}  // namespace vislib_test
