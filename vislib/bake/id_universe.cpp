// id_universe.cpp: the id rule of id_universe.h.
#include "vislib/bake/id_universe.h"

#include <algorithm>
#include <cassert>

namespace vislib {

uint32_t id_universe(const Scene& scene, Granularity g) {
  uint64_t n = g == Granularity::Object ? scene.objects.size()
                                             : scene.triangle_count() + scene.sphere_count();
  assert(n < 0xFFFFFFFFull);
  return uint32_t(n);
}

IdTarget id_target(const Scene& scene, Granularity g, uint32_t id) {
  assert(id < id_universe(scene, g));
  if (g == Granularity::Object) return {IdTarget::Object, id};
  if (id < scene.triangle_count()) return {IdTarget::Triangle, id};
  return {IdTarget::Sphere, uint32_t(id - scene.triangle_count())};
}

std::vector<uint32_t> ids_of(const Scene& scene, Granularity g,
                             const std::vector<uint32_t>& triangles,
                             const std::vector<uint32_t>& spheres) {
  std::vector<uint32_t> out;
  out.reserve(triangles.size() + spheres.size());
  if (g == Granularity::Object) {
    for (uint32_t t : triangles) out.push_back(scene.triangle_object[t]);
    for (uint32_t s : spheres) out.push_back(scene.sphere_object[s]);
  } else {
    out = triangles;
    for (uint32_t s : spheres) out.push_back(uint32_t(scene.triangle_count() + s));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Primitives primitives_of(const Scene& scene, Granularity g, const std::vector<uint32_t>& ids) {
  Primitives p;
  if (g == Granularity::Object) {
    std::vector<uint8_t> keep(scene.objects.size(), 0);
    for (uint32_t o : ids) keep[o] = 1;
    for (uint32_t t = 0; t < scene.triangle_count(); ++t)
      if (keep[scene.triangle_object[t]]) p.triangles.push_back(t);
    for (uint32_t s = 0; s < scene.sphere_count(); ++s)
      if (keep[scene.sphere_object[s]]) p.spheres.push_back(s);
    return p;
  }
  for (uint32_t id : ids) {
    IdTarget t = id_target(scene, g, id);
    (t.kind == IdTarget::Triangle ? p.triangles : p.spheres).push_back(t.index);
  }
  std::sort(p.triangles.begin(), p.triangles.end());
  std::sort(p.spheres.begin(), p.spheres.end());
  return p;
}

}  // namespace vislib
