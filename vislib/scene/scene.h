// scene.h: the scene model. Plain data, no class hierarchy (house style §2).
//
// Coordinates are double everywhere (not float with an origin): a 1 cm triangle 1e5 m from the
// origin keeps ~1e-11 m resolution, and the visibility kernels re-centre at the eye in double
// (docs/visibility-math.md §6).
//
// Triangle ids are the indices into `triangles`. Their order is stable and documented in
// docs/scene-model.md: importers append triangles in file order (glTF: default scene's root nodes
// in order, depth-first, children in order, primitives in order, triangles in index order; OBJ/PLY/
// OFF/STL: face order in the file). `pvs export` writes them in this order, so ids are checkable.
//
// Dynamic scenes: K >= 1 key states. `positions[k][v]` is vertex v in state k and
// `sphere_centers[k][s]` is sphere s in state k. Between states motion is piecewise linear:
// animation time tau in [0,1] maps to state interval floor(tau*(K-1)).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vislib/base/vec.h"

namespace vislib {

// An object's triangles are either opaque (the default) or see-through. A see-through triangle
// is seen but hides nothing (water, glass, windows, foliage cards): it is visible from an eye
// along a direction where no opaque surface lies in front of it (a depth tie with an opaque
// surface counts as visible), and every surface behind it stays visible through it. The class is
// per object because it is a property of the material, and an object is what every format names
// (glTF node, OBJ group, BSP texture); docs/scene-model.md "See-through objects". Spheres are
// always opaque: the kernels refuse a see-through object with spheres.
struct Object {
  std::string name;          // glTF node/mesh name, OBJ group/object name, or generated name
  bool see_through = false;  // its triangles are seen but do not occlude
  // The materials whose alpha mode made the object see-through on import (glTF BLEND, or MASK
  // whose alpha can fall below its cutoff: docs/scene-model.md "See-through objects"), by name
  // ("material N" when unnamed), in primitive order, each once. Empty for every other object.
  std::vector<std::string> alpha_materials = {};
};

struct Scene {
  // positions[state][vertex]; every state has the same vertex count. At least one state when
  // the scene has triangles or spheres.
  std::vector<std::vector<Vec3>> positions;
  // Triangles as vertex indices (each < vertex_count()). Triangle id = index here.
  std::vector<std::array<uint32_t, 3>> triangles;
  // Object of each triangle (index into `objects`); same length as `triangles`.
  std::vector<uint32_t> triangle_object;
  std::vector<Object> objects;
  // Sphere particles: radius per sphere, centres per state (sphere_centers[state][sphere]).
  std::vector<double> sphere_radius;
  std::vector<std::vector<Vec3>> sphere_centers;
  // Object of each sphere (index into `objects`).
  std::vector<uint32_t> sphere_object;

  size_t state_count() const {
    return positions.size() > sphere_centers.size() ? positions.size() : sphere_centers.size();
  }
  size_t vertex_count() const { return positions.empty() ? 0 : positions[0].size(); }
  size_t triangle_count() const { return triangles.size(); }
  size_t sphere_count() const { return sphere_radius.size(); }
  // True when some vertex or sphere centre differs between states.
  bool is_dynamic() const;
  // Vertex position at animation time tau in [0,1] (piecewise linear between states).
  Vec3 position_at(uint32_t vertex, double tau) const;
  Vec3 sphere_center_at(uint32_t sphere, double tau) const;
  // Corners of triangle `tri` in state `state`.
  std::array<Vec3, 3> corners(uint32_t tri, size_t state = 0) const {
    const auto& p = positions[state];
    const auto& t = triangles[tri];
    return {p[t[0]], p[t[1]], p[t[2]]};
  }
  // True when triangle `tri` belongs to a see-through object.
  bool triangle_see_through(uint32_t tri) const {
    return objects[triangle_object[tri]].see_through;
  }
  // True when some object is see-through; an O(objects) scan.
  bool has_see_through() const;
  // Number of triangles of see-through objects.
  size_t see_through_triangle_count() const;
  // Bounding box over all states of vertices and spheres (radius included).
  Box3 bounds() const;
};

// Appends `other` to `scene` (ids of `other` follow those of `scene`). Both must have the same
// state count, or one of them a single state (which is then repeated).
void append_scene(Scene& scene, const Scene& other);

// Marks every object whose name matches one of `patterns` (shell globs as fnmatch(3) reads them,
// without flags: `*`, `?` and `[...]`; a literal `*` is `[*]`) see-through. Returns the number of
// objects it marked (already see-through ones included). This is the call an importer or a
// command-line option makes; an importer that knows its materials may set Object::see_through
// itself.
size_t mark_see_through(Scene& scene, const std::vector<std::string>& patterns);

// Keeps opaque, whatever their alpha mode, the objects whose name matches one of `patterns`
// (shell globs as in mark_see_through) and the materials whose name matches one: a matched
// material leaves every object's alpha_materials, and an object becomes opaque when its name
// matched or when it was see-through by its alpha materials and none is left. Returns, for each
// pattern in order, how many object names and alpha materials (once per object) it matched.
std::vector<size_t> keep_opaque(Scene& scene, const std::vector<std::string>& patterns);

}  // namespace vislib
