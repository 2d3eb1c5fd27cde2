// free_space.cpp: enclosure probing of points and view cells by brute-force rays (free_space.h).
#include "vislib/bake/free_space.h"

#include <array>
#include <cmath>
#include <vector>

#include "vislib/base/ray_triangle.h"

namespace vislib {

namespace {

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
      if (hit && *hit > 0 && *hit < best) {
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
