// scene_subset.cpp: a scene reduced to a set of triangle or object ids.
#include "vislib/bake/scene_subset.h"

#include <cassert>

#include "vislib/bake/id_universe.h"

namespace vislib {

SceneAppearance appearance_subset(const Scene& scene, const SceneAppearance& appearance,
                                  const std::vector<uint32_t>& ids, Granularity granularity) {
  SceneAppearance out = appearance;
  if (appearance.triangle_material.size() != scene.triangle_count()) return out;
  Primitives prims = primitives_of(scene, granularity, ids);
  std::vector<uint8_t> keep(scene.triangle_count(), 0);
  for (uint32_t t : prims.triangles) keep[t] = 1;
  out.triangle_material.clear();
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[t]) out.triangle_material.push_back(appearance.triangle_material[t]);
  return out;
}

Scene scene_subset(const Scene& scene, const std::vector<uint32_t>& ids, Granularity granularity) {
  // The ids are read with the bake's one id rule (bake/id_universe.h).
  Primitives prims = primitives_of(scene, granularity, ids);
  std::vector<uint8_t> keep(scene.triangle_count(), 0), keep_sphere(scene.sphere_count(), 0);
  for (uint32_t t : prims.triangles) keep[t] = 1;
  for (uint32_t s : prims.spheres) keep_sphere[s] = 1;
  std::vector<uint32_t> used(scene.objects.size(), 0);
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[t]) used[scene.triangle_object[t]] = 1;
  for (size_t s = 0; s < scene.sphere_count(); ++s)
    if (keep_sphere[s]) used[scene.sphere_object[s]] = 1;
  Scene out;
  out.positions = scene.positions;
  std::vector<uint32_t> new_id(scene.objects.size(), 0);
  for (size_t o = 0; o < scene.objects.size(); ++o)
    if (used[o]) {
      new_id[o] = uint32_t(out.objects.size());
      out.objects.push_back(scene.objects[o]);
    }
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[t]) {
      out.triangles.push_back(scene.triangles[t]);
      out.triangle_object.push_back(new_id[scene.triangle_object[t]]);
    }
  if (!prims.spheres.empty()) {
    out.sphere_centers.resize(scene.sphere_centers.size());
    for (size_t s = 0; s < scene.sphere_count(); ++s) {
      if (!keep_sphere[s]) continue;
      for (size_t k = 0; k < scene.sphere_centers.size(); ++k)
        out.sphere_centers[k].push_back(scene.sphere_centers[k][s]);
      out.sphere_radius.push_back(scene.sphere_radius[s]);
      out.sphere_object.push_back(new_id[scene.sphere_object[s]]);
    }
  }
  return out;
}

}  // namespace vislib
