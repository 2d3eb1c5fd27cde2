// id_universe.h: the one rule mapping a scene to the ids a PVS stores, and an id back to a
// triangle, sphere or object (docs/pvs-format.md "Ids"). The bake writes ids with it; inspect and
// view check a file's universe and read its ids with it.
//
//   triangle granularity: triangle t is id t; sphere s is id triangle_count + s;
//                         universe = triangle_count + sphere_count
//   object granularity:   object o is id o; universe = object count (spheres are objects too)
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The number of ids of `scene` at granularity `g`. Scenes must have fewer than 2^32 - 1 ids.
uint32_t id_universe(const Scene& scene, Granularity g);

// What an id names. kind Triangle/Sphere/Object, index into the scene's triangles, spheres or
// objects.
struct IdTarget {
  enum Kind : uint8_t { Triangle, Sphere, Object };
  Kind kind = Triangle;
  uint32_t index = 0;
};
// `id` must be < id_universe(scene, g).
IdTarget id_target(const Scene& scene, Granularity g, uint32_t id);

// The ids (sorted, unique) of visible triangles and spheres at granularity g: the ids of the
// primitives (triangle granularity) or of their objects (object granularity).
std::vector<uint32_t> ids_of(const Scene& scene, Granularity g,
                             const std::vector<uint32_t>& triangles,
                             const std::vector<uint32_t>& spheres);

// The triangles and spheres (each sorted) that `ids` stand for: the primitives themselves
// (triangle granularity) or every primitive of the objects (object granularity). Every id must
// be < id_universe(scene, g).
struct Primitives {
  std::vector<uint32_t> triangles, spheres;
};
Primitives primitives_of(const Scene& scene, Granularity g, const std::vector<uint32_t>& ids);

}  // namespace vislib
