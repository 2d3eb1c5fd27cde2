// scene_subset.cpp: a scene reduced to a set of triangle or object ids.
#include "vislib/bake/scene_subset.h"

#include <cassert>

namespace vislib {

namespace {

std::vector<uint8_t> kept(const Scene& scene, const std::vector<uint32_t>& ids,
                          Granularity granularity) {
  std::vector<uint8_t> keep(scene.triangle_count(), 0);
  if (granularity == Granularity::Triangle) {
    for (uint32_t t : ids) {
      assert(t < scene.triangle_count());
      keep[t] = 1;
    }
  } else {
    std::vector<uint8_t> object(scene.objects.size(), 0);
    for (uint32_t o : ids) {
      assert(o < scene.objects.size());
      object[o] = 1;
    }
    for (size_t t = 0; t < scene.triangle_count(); ++t) keep[t] = object[scene.triangle_object[t]];
  }
  return keep;
}

}  // namespace

SceneAppearance appearance_subset(const Scene& scene, const SceneAppearance& appearance,
                                  const std::vector<uint32_t>& ids, Granularity granularity) {
  SceneAppearance out = appearance;
  if (appearance.triangle_material.size() != scene.triangle_count()) return out;
  std::vector<uint8_t> keep = kept(scene, ids, granularity);
  out.triangle_material.clear();
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[t]) out.triangle_material.push_back(appearance.triangle_material[t]);
  return out;
}

Scene scene_subset(const Scene& scene, const std::vector<uint32_t>& ids, Granularity granularity) {
  std::vector<uint8_t> keep = kept(scene, ids, granularity);
  std::vector<uint32_t> used(scene.objects.size(), 0);
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[t]) used[scene.triangle_object[t]] = 1;
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
  return out;
}

}  // namespace vislib
